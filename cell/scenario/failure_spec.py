"""The ``failures:`` section checked, and its random times drawn (docs/model.md, "When
equipment fails").

Each failure mode (an equipment's time to failure, its time to repair) draws from its own
child stream of the run's SeedSequence, keyed by :data:`STREAM_KEYS`, so replication r gives
every policy the same parts (the feeder's stream 0) and the same failure draws.  Times are
drawn by inverse cdf, u ~ U(0, 1) then scipy.stats' ``ppf``, in blocks (one ``ppf`` call
per block, not per draw).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from cell.plumbing.errors import ScenarioError
from cell.scenario.arrivals import stream
from cell.scenario.spread import BY_MEAN_AND_CV, by_mean

#: Pieces of equipment that can fail, in the order states.csv lists them.
EQUIPMENT = ("robot", "input_belt", "output_belt", "sensor")
#: The child streams of the run's root SeedSequence: (time to failure, time to repair) per
#: equipment.  The feeder's is 0 and the wear clock's 21; these keep clear of both.
STREAM_KEYS = {name: (2100 + 2 * i, 2101 + 2 * i) for i, name in enumerate(EQUIPMENT)}
#: Draws made per ``ppf`` call.
BLOCK = 256
SECONDS_PER_HOUR = 3600.0
#: The shortest mean time between the stops of one cause (a failure mode, planned maintenance,
#: motor wear), a time longer than the run counted as the run: a run then stops at most about
#: twice a simulated second for each cause (see :func:`mean_within`), however it is specified.
MIN_MEAN_S = 1.0
#: Points of the integral :func:`mean_within` sums.
GRID = 2048


def check_failures(f: Any, file: object, run_s: float = math.inf) -> None:
    """Refuse times that scipy rejects, can be negative, or have no finite positive mean,
    planned stops longer than their interval, and stops so frequent that a run of ``run_s``
    seconds would be an event storm (:func:`check_frequency`)."""
    if f is None:
        return
    for name in EQUIPMENT:
        mode = getattr(f, name)
        if mode is None:
            continue
        for which in ("time_to_failure", "time_to_repair"):
            check_time(getattr(mode, which), f"failures.{name}.{which}", file)
        given, value = as_given(mode.time_to_failure)
        check_frequency(frozen(mode.time_to_failure), run_s, file,
                        f"failures.{name}.time_to_failure.{given}", value, "fails every")
    m = f.maintenance
    if m is not None:
        if m.duration_min * 60.0 >= m.every_h * SECONDS_PER_HOUR:
            raise ScenarioError(file, "failures.maintenance.duration_min", m.duration_min,
                                f"a planned stop must be shorter than its interval "
                                f"(failures.maintenance.every_h = {m.every_h:g} h)")
        every_s = m.every_h * SECONDS_PER_HOUR
        if min(every_s, run_s) < floor_s(run_s):
            raise ScenarioError(file, "failures.maintenance.every_h", m.every_h,
                                f"a planned stop every {every_s:.3g} s: at least "
                                f"{floor_s(run_s):g} s apart, or a run is mostly stops")


def check_wear(w: Any, file: object, run_s: float = math.inf) -> None:
    """Refuse motor lives so short that a run would be an event storm: the robot's time to a
    worn motor, five motors in series all at the peak stress (S = 1, where the life is
    shortest: η0 S0^p), held to :func:`check_frequency`'s rule."""
    if not w.enabled:
        return
    import scipy.stats

    motor_s = w.rated_life_h * w.reference_stress ** w.exponent * SECONDS_PER_HOUR
    robot = scipy.stats.weibull_min(w.shape, scale=motor_s / 5.0 ** (1.0 / w.shape))
    check_frequency(robot, run_s, file, "wear.rated_life_h", w.rated_life_h,
                    f"wears a motor out (one of five, each of life {w.rated_life_h:g} h x "
                    f"{w.reference_stress:g}^{w.exponent:g} at the peak stress) every")


def floor_s(run_s: float) -> float:
    """The shortest mean time between stops a run of ``run_s`` seconds accepts: MIN_MEAN_S, or
    half the run if it is shorter than two of them (a run that short stops a few times at most)."""
    return min(MIN_MEAN_S, run_s / 2.0)


def mean_within(dist: Any, run_s: float) -> float:
    """E[min(X, T)] = ∫_0^T P(X > t) dt: the mean of a time X, a time longer than the run's T
    counted as T; from above, within 2 %.

    It bounds the stops a run brings, whatever X's shape: the renewal process of
    Y = min(X, T) stops at least as often in [0, T] as X's, and its stop after T comes by
    2 T, so by Wald's identity E[N(T)] < 2 T / E[Y].  A distribution whose mean is long
    only through rare enormous draws, nearly every draw a microsecond, has a short E[Y].
    The integral is the upper sum of the decreasing P(X > t) over GRID points spaced
    geometrically from T 1e-15 to T (each step 1.7 % of t, so the sum is within 2 % of the
    integral), plus T 1e-15 for the stretch below."""
    t = np.geomspace(run_s * 1e-15, run_s, GRID)
    sf = np.asarray(dist.sf(t[:-1]), dtype=float)
    return float(t[0] + np.sum(np.diff(t) * np.nan_to_num(sf, nan=1.0)))


def check_frequency(dist: Any, run_s: float, file: object, key: str, value: Any, what: str) -> None:
    """Refuse a time between stops (a time to failure, a motor's life) whose mean within the
    run (:func:`mean_within`) is shorter than :func:`floor_s`: a run of ``run_s`` s would stop
    more than about twice a simulated second for this cause alone, an event storm."""
    if min(float(dist.ppf(0.5)), run_s) >= 2.0 * floor_s(run_s):
        return  # E[min(X, T)] >= min(median, T) / 2 >= the floor: no need to count
    within = mean_within(dist, run_s)
    if within < floor_s(run_s):
        raise ScenarioError(file, key, value,
                            f"{what} {within:.3g} s on average (a time longer than the run's "
                            f"{run_s:.4g} s counted as the run): at least {floor_s(run_s):g} s, "
                            "or a run is mostly stops")


def mean_seconds(spec: Any) -> float | None:
    """The mean a time is given by, in seconds (``mean_s``, or ``mean_h`` × 3600); None for
    a time given by its scipy ``params``."""
    if spec.mean_h is not None:
        return float(spec.mean_h) * SECONDS_PER_HOUR
    return None if spec.mean_s is None else float(spec.mean_s)


def scipy_params(spec: Any) -> dict[str, float]:
    """A time's scipy parameters: its ``params``, or those of its mean and its shape or cv
    (:func:`cell.scenario.spread.by_mean`; a ValueError where there are none)."""
    mean = mean_seconds(spec)
    if mean is None:
        return dict(spec.params)
    return by_mean(spec.distribution, mean, shape=spec.shape, cv=spec.cv)


def as_given(spec: Any) -> tuple[str, Any]:
    """The key a time was given by (``params``, ``mean_s`` or ``mean_h``) and its value, as a
    message about the time names them."""
    for key in ("mean_h", "mean_s"):
        if getattr(spec, key) is not None:
            return key, getattr(spec, key)
    return "params", dict(spec.params)


def unit(spec: Any) -> str:
    """The unit a time was given in: ``h`` for ``mean_h``, ``s`` otherwise."""
    return "h" if spec.mean_h is not None else "s"


def frozen(spec: Any) -> Any:
    """The scipy.stats distribution of a time setting (:func:`scipy_params`)."""
    import scipy.stats

    return getattr(scipy.stats, spec.distribution)(**scipy_params(spec))


def check_by_mean(spec: Any, key: str, file: object) -> None:
    """Refuse a time given half by its mean, or by its mean in two ways: ``mean_s`` with
    ``mean_h``, ``shape`` with ``cv``, ``params`` with a mean, a shape or cv without a mean,
    a family the mean cannot set, an exponential with a shape or cv, a mean alone for a
    family that needs its spread too."""
    mean_key, mean = as_given(spec)
    spread = [(k, getattr(spec, k)) for k in ("shape", "cv") if getattr(spec, k) is not None]
    if spec.mean_s is not None and spec.mean_h is not None:
        raise ScenarioError(file, f"{key}.mean_h", spec.mean_h,
                            f"give {key}.mean_s or {key}.mean_h, not both")
    if len(spread) == 2:
        raise ScenarioError(file, f"{key}.cv", spec.cv, f"give {key}.shape or {key}.cv, not both")
    if mean_key == "params":
        if spread:
            raise ScenarioError(file, f"{key}.{spread[0][0]}", spread[0][1],
                                f"goes with {key}.mean_s or {key}.mean_h (or give {key}.params "
                                "alone)")
        return
    if spec.params:
        raise ScenarioError(file, f"{key}.params", dict(spec.params),
                            f"give {key}.params or {key}.{mean_key}, not both")
    if spec.distribution not in BY_MEAN_AND_CV:
        raise ScenarioError(file, f"{key}.distribution", spec.distribution,
                            f"a time by its mean is one of {', '.join(BY_MEAN_AND_CV)}; give "
                            f"{key}.params for {spec.distribution}")
    if spec.distribution == "expon" and spread:
        raise ScenarioError(file, f"{key}.{spread[0][0]}", spread[0][1],
                            f"expon is set by {key}.{mean_key} alone")
    if not spread and spec.distribution != "expon":
        raise ScenarioError(file, f"{key}.{mean_key}", mean,
                            f"{spec.distribution} needs {key}.shape or {key}.cv beside its mean")
    try:
        scipy_params(spec)
    except ValueError as exc:
        raise ScenarioError(file, f"{key}.{spread[0][0]}", spread[0][1],
                            f"{spec.distribution}: {exc}") from None


def check_time(spec: Any, key: str, file: object) -> float:
    """A time distribution's mean, after refusing what cannot be one."""
    import scipy.stats

    dist = getattr(scipy.stats, spec.distribution, None)
    if not isinstance(dist, scipy.stats.rv_continuous):
        raise ScenarioError(file, f"{key}.distribution", spec.distribution,
                            "not a continuous distribution in scipy.stats")
    check_by_mean(spec, key, file)
    given, value = as_given(spec)
    try:
        d = frozen(spec)
        mean, low = float(d.mean()), float(d.support()[0])
    except (TypeError, ValueError) as exc:
        raise ScenarioError(file, f"{key}.{given}", value,
                            f"not accepted by scipy.stats.{spec.distribution}: {exc}") from None
    if math.isnan(mean) and math.isnan(low):  # scipy's answer for parameters out of range
        raise ScenarioError(file, f"{key}.{given}", value,
                            f"scipy.stats.{spec.distribution} takes no such parameters (a zero "
                            "or negative scale?): the mean time would be undefined")
    if not math.isfinite(mean):  # infinite, or undefined (a Cauchy's)
        raise ScenarioError(file, f"{key}.{given}", value,
                            f"scipy.stats.{spec.distribution} with these has no finite mean")
    if not low >= 0 or not mean > 0:
        raise ScenarioError(file, f"{key}.{given}", value,
                            f"times must be non-negative with a positive mean (mean {mean:.6g} s)")
    return mean


class Draws:
    """Times from one distribution, drawn from one stream in blocks, handed out one by one."""

    def __init__(self, spec: Any, seed: int | np.random.SeedSequence, key: int):
        self.dist, self.rng = frozen(spec), stream(seed, key)
        self.left: list[float] = []

    def __call__(self) -> float:
        left = self.left
        if not left:
            u = self.rng.random(BLOCK)
            left.extend(reversed(np.asarray(self.dist.ppf(u), dtype=float).tolist()))
        return left.pop()
