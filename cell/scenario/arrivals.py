"""The parts supply's numbers: inter-arrival times (thesis §6.2 d, eq. 6.9).

Times are drawn by inverse cdf: u ~ U(0, 1) from the feeder's own numpy stream,
T = F⁻¹(u) with scipy.stats' ``ppf``.  For the default Weibull that is eq. 6.9,
T = 17.6019 + 5.4342 (-ln(1 - u))^0.2038; it and the exponential are computed
here with numpy, to the bit as scipy does (:func:`closed_form_ppf`), so a run of
them needs no scipy.  The stream is a child of the run's
SeedSequence that nothing else uses, so every policy run with the same seed sees
the same parts (common random numbers).  A CSV trace of observed times replaces
the distribution when given.  With ``arrivals.profile`` the rate changes over a repeating
period: the same draws, laid out in operational time and mapped to the run's time through
the integrated rate (:mod:`cell.scenario.rate_profile`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from cell.plumbing.cache import Remembered, file_key, memo
from cell.plumbing.errors import ScenarioError
from cell.scenario.rate_profile import ProfileSpec, check_profile, scaled_gaps
from cell.scenario.spread import BY_MEAN_AND_CV, by_mean_and_cv
from cell.scenario.trace_file import column_cells

#: The feeder's child stream of the root SeedSequence (other streams take other keys).
FEEDER_STREAM = 0
#: No inter-arrival time (a trace's) or mean (a distribution's) may exceed this, s.
MAX_INTERARRIVAL_S = 1e6


class ArrivalSpec(Protocol):
    """What the supply needs of a scenario's ``arrivals`` section."""

    @property
    def distribution(self) -> str: ...
    @property
    def params(self) -> Mapping[str, float]: ...
    @property
    def trace_csv(self) -> str | None: ...
    @property
    def mean_s(self) -> float | None: ...
    @property
    def cv(self) -> float | None: ...
    @property
    def profile(self) -> ProfileSpec | None: ...


def root_seed(seed: int | np.random.SeedSequence) -> np.random.SeedSequence:
    """The run's root SeedSequence from an int or a SeedSequence (never mutated)."""
    if isinstance(seed, np.random.SeedSequence):
        return seed
    return np.random.SeedSequence(int(seed))


def stream(seed: int | np.random.SeedSequence, key: int) -> np.random.Generator:
    """The ``key``-th child stream of the root, without spawning (which would mutate it).

    Same as ``root.spawn(key + 1)[key]`` on a fresh root, but repeatable on a
    SeedSequence that is passed around (e.g. to both policies of a sweep).
    """
    root = root_seed(seed)
    child = np.random.SeedSequence(root.entropy, spawn_key=(*root.spawn_key, key),
                                   pool_size=root.pool_size)
    return np.random.default_rng(child)


def interarrival_times(arrivals: ArrivalSpec, n: int, seed: int | np.random.SeedSequence,
                       base_dir: Path | str = ".") -> NDArray[np.float64]:
    """The first ``n`` inter-arrival times (s) of a run: eq. 6.9 by default.

    With ``arrivals.trace_csv`` the trace's times are used in order, repeating
    from its start if the run needs more than it holds.  With ``arrivals.profile`` the
    distribution's draws are time-scaled by the profile's integrated rate
    (:func:`~cell.scenario.rate_profile.scaled_gaps`).
    """
    if arrivals.trace_csv is not None:
        trace = read_trace(Path(base_dir) / arrivals.trace_csv)
        return np.resize(trace, n).astype(float)
    times = _stationary_times(arrivals, n, seed)
    return times if arrivals.profile is None else scaled_gaps(times, arrivals.profile)


def _stationary_times(arrivals: ArrivalSpec, n: int,
                      seed: int | np.random.SeedSequence) -> NDArray[np.float64]:
    u = stream(seed, FEEDER_STREAM).random(n)
    facts = _known_facts(arrivals)
    params = facts[0] if facts is not None else parameters(arrivals)
    times = closed_form_ppf(arrivals.distribution, params, u)
    if times is not None:
        return times
    import scipy.stats

    frozen = getattr(scipy.stats, arrivals.distribution)(**params)
    return np.asarray(frozen.ppf(u), dtype=float)


# --------------------------------------------------------------------------- draws
#: Cephes' log1p (scipy.special.log1p): log(1 + x) = x - x²/2 + x³ P(x)/Q(x) on
#: [1/√2 - 1, √2 - 1], libm's log(1 + x) outside.
_LOG1P_P = (4.5270000862445199635215e-5, 4.9854102823193375972212e-1,
            6.5787325942061044846969e0, 2.9911919328553073277375e1,
            6.0949667980987787057556e1, 5.7112963590585538103336e1,
            2.0039553499201281259648e1)
_LOG1P_Q = (1.5062909083469192043167e1, 8.3047565967967209469434e1,
            2.2176239823732856465394e2, 3.0909872225312059774938e2,
            2.1642788614495947685003e2, 6.0118660497603843919306e1)


def log1p_as_scipy(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """``scipy.special.log1p(x)`` bit for bit, with numpy and the C library's ``log``.

    numpy's own ``log1p`` (and, on some CPUs, its vectorised ``log``) differs from
    scipy's in the last bit on some inputs; this follows scipy's Cephes code step
    by step: the same polynomial evaluated in the same order (IEEE arithmetic is
    exact whatever the vectorisation), ``math.log`` where Cephes calls ``log``.
    """
    z = 1.0 + x
    out = np.empty_like(x)
    far = (z < math.sqrt(0.5)) | (z > math.sqrt(2.0))
    zf = z[far]
    if zf.size and zf.min() > 0:
        out[far] = list(map(math.log, zf.tolist()))
    else:  # math.log refuses what C's log maps to -inf or NaN
        out[far] = [math.log(v) if v > 0 else (-math.inf if v == 0 else math.nan)
                    for v in zf.tolist()]
    near = ~far
    xs = x[near]
    p = np.full_like(xs, _LOG1P_P[0])
    for c in _LOG1P_P[1:]:
        p = p * xs + c
    q = xs + _LOG1P_Q[0]
    for c in _LOG1P_Q[1:]:
        q = q * xs + c
    zz = xs * xs
    zz = -0.5 * zz + xs * (zz * p / q)
    out[near] = xs + zz
    return out


#: Families whose inverse cdf is drawn here with numpy: eq. 6.9's Weibull and the
#: exponential, as scipy.stats would (their parameters, in scipy's names).
CLOSED_FORM = {"weibull_min": ("c", "loc", "scale"), "expon": ("loc", "scale")}


def closed_form_ppf(family: str, params: Mapping[str, float],
                    u: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """``scipy.stats.<family>(**params).ppf(u)`` to the bit, without scipy, for the
    families of :data:`CLOSED_FORM` (None for others, or for what scipy would treat
    specially: parameters out of range, u = 0).

    scipy computes weibull_min's as ``pow(-log1p(-u), 1/c) * scale + loc`` and
    expon's as ``-log1p(-u) * scale + loc``, each parameter broadcast to an array
    the length of u; the same numpy operations on the same arrays give the same bits.
    """
    names = CLOSED_FORM.get(family)
    if names is None or not set(params) <= set(names) or u.ndim != 1 or not u.size:
        return None
    c = params.get("c", math.nan if family == "weibull_min" else 1.0)
    loc, scale = params.get("loc", 0.0), params.get("scale", 1.0)
    if not all(type(v) in (float, int) and math.isfinite(v) for v in (c, loc, scale)) \
            or not (c > 0 and scale > 0) or not bool(np.all((u > 0) & (u < 1))):
        return None
    n = u.size
    tail = -log1p_as_scipy(-u)
    if family == "weibull_min":
        tail = np.power(tail, 1.0 / np.full(n, float(c)))  # scipy's pow(...) on arrays
    return np.asarray(tail * np.full(n, float(scale)) + np.full(n, float(loc)), dtype=float)


# --------------------------------------------------------------------------- facts
def _facts_key(arrivals: ArrivalSpec) -> dict[str, Any]:
    return {"distribution": arrivals.distribution, "params": dict(arrivals.params),
            "mean_s": arrivals.mean_s, "cv": arrivals.cv}


def _facts_from_plain(plain: Any) -> tuple[dict[str, float], float, float]:
    return ({str(k): float(v) for k, v in plain["params"].items()}, float(plain["mean"]),
            float(plain["low"]))


def _facts_to_plain(facts: tuple[dict[str, float], float, float]) -> dict[str, Any]:
    params, mean, low = facts
    return {"params": params, "mean": mean, "low": low}


#: (scipy parameters, mean, lower end of the support) of arrivals that passed
#: :func:`check_arrivals`, here or in an earlier process; and the families scipy has.
_FACTS: Remembered[tuple[dict[str, float], float, float]] = Remembered(
    "arrivals", _facts_to_plain, _facts_from_plain)
_FAMILIES: Remembered[bool] = Remembered("family")


def _known_facts(arrivals: ArrivalSpec) -> tuple[dict[str, float], float, float] | None:
    return _FACTS.get(_facts_key(arrivals))


def _remember(arrivals: ArrivalSpec, params: dict[str, float], mean: float, low: float) -> None:
    _FACTS.put(_facts_key(arrivals), (dict(params), mean, low))


def _frozen(arrivals: ArrivalSpec) -> Any:
    import scipy.stats

    return getattr(scipy.stats, arrivals.distribution)(**parameters(arrivals))


def parameters(arrivals: ArrivalSpec) -> dict[str, float]:
    """The distribution's scipy parameters: ``params``, or those derived from ``mean_s``
    and ``cv`` (no location, except the shifted exponential's)."""
    if arrivals.mean_s is None or arrivals.cv is None:
        return dict(arrivals.params)
    return by_mean_and_cv(arrivals.distribution, arrivals.mean_s, arrivals.cv)


def mean_interarrival(arrivals: ArrivalSpec, base_dir: Path | str = ".") -> float:
    """The mean inter-arrival time (s): the distribution's, or the trace's; with a profile,
    the long run's (its rates are normalised to a mean of 1)."""
    if arrivals.trace_csv is not None:
        return float(np.mean(read_trace(Path(base_dir) / arrivals.trace_csv)))
    facts = _known_facts(arrivals)
    if facts is not None:
        return facts[1]
    return float(_frozen(arrivals).mean())


def check_arrivals(arrivals: ArrivalSpec, base_dir: Path, file: object) -> None:
    """Refuse a distribution scipy does not have, parameters it rejects, times that
    can be negative or have no finite mean, and an unusable trace.

    What passed is remembered (:mod:`cell.plumbing.cache`, on disk too), so a later start
    checks the same arrivals without importing scipy.stats.  A profile is checked by
    :func:`~cell.scenario.rate_profile.check_profile`."""
    if arrivals.profile is not None:
        check_profile(arrivals.profile, arrivals.trace_csv, file)
    if arrivals.trace_csv is None and _known_facts(arrivals) is not None:
        return
    family = {"distribution": arrivals.distribution}
    if _FAMILIES.get(family) is not True:
        import scipy.stats

        dist = getattr(scipy.stats, arrivals.distribution, None)
        if not isinstance(dist, scipy.stats.rv_continuous):
            raise ScenarioError(file, "arrivals.distribution", arrivals.distribution,
                                "not a continuous distribution in scipy.stats")
        _FAMILIES.put(family, True)
    if arrivals.trace_csv is not None:
        read_trace(base_dir / arrivals.trace_csv, file)
        return
    if (arrivals.mean_s is None) != (arrivals.cv is None):
        key = "arrivals.cv" if arrivals.cv is None else "arrivals.mean_s"
        raise ScenarioError(file, key, None, "give arrivals.mean_s and arrivals.cv together")
    try:
        params = parameters(arrivals)
    except ValueError as exc:
        raise ScenarioError(file, "arrivals.cv", arrivals.cv,
                            f"{arrivals.distribution}: {exc}") from None
    import scipy.stats

    dist = getattr(scipy.stats, arrivals.distribution)
    mismatch = _misnamed(arrivals.distribution, params)
    if mismatch:
        raise ScenarioError(file, "arrivals.params", params, mismatch)
    try:
        frozen = dist(**params)
        mean = float(frozen.mean())
        low = float(frozen.support()[0])
    except (TypeError, ValueError) as exc:
        raise ScenarioError(file, "arrivals.params", params,
                            f"not accepted by scipy.stats.{arrivals.distribution}: {exc}") from None
    if not math.isfinite(mean) or not low >= 0 or not mean > 0:
        raise ScenarioError(file, "arrivals.params", params,
                            "inter-arrival times must be non-negative with a finite, positive mean")
    if mean > MAX_INTERARRIVAL_S:
        raise ScenarioError(file, "arrivals.params", params,
                            f"the mean inter-arrival time would be {mean:.10g} s; at most "
                            f"{MAX_INTERARRIVAL_S:g} s")
    _remember(arrivals, params, mean, low)


def param_names(dist: Any) -> list[str]:
    """A scipy.stats distribution's parameters by name: its shapes, ``loc``, ``scale``."""
    return [*(s.strip() for s in (dist.shapes or "").split(",") if s.strip()), "loc", "scale"]


def _misnamed(family: str, params: Mapping[str, float]) -> str:
    """Why ``params`` are not ``family``'s by name (another family's, a shape missing), with
    the fix; "" when the names fit (scipy.stats then judges the values)."""
    import scipy.stats

    names = param_names(getattr(scipy.stats, family))
    alien = [k for k in params if k not in names]
    missing = [k for k in names[:-2] if k not in params]
    if not alien and not missing:
        return ""
    owners = [f for f in BY_MEAN_AND_CV if f != family and alien and
              set(params) <= set(param_names(getattr(scipy.stats, f)))]
    wrong = (f"not {', '.join(alien)}" + (f" ({owners[0]}'s)" if owners else "") if alien else
             f"{', '.join(missing)} missing")
    fix = f"give arrivals.params for {family}" + \
        (", or arrivals.mean_s and arrivals.cv" if family in BY_MEAN_AND_CV else "")
    return f"arrivals.distribution {family} takes {', '.join(names)}, {wrong}: {fix}"


def read_trace(path: Path, file: object = None) -> NDArray[np.float64]:
    """Inter-arrival times from a CSV trace: one column ``interarrival_s``, all ≥ 0 (a line's
    log stamped to the second has 0 between parts that came in the same second; the feeder
    holds such a part until the belt has carried the last one clear), their mean > 0.

    Parsed once per version of the file (path, size, modification time), so a
    sweep's replications do not read it again.  The array is read-only.
    """
    if not path.is_file():
        raise ScenarioError(file or path, "arrivals.trace_csv", str(path), "no such file")
    times = _parse_trace(path)
    if isinstance(times, str):
        raise ScenarioError(file or path, "arrivals.trace_csv", str(path), times)
    return times


@memo(key=file_key)
def _parse_trace(path: Path) -> Any:
    """The trace's times, or why they cannot be used (a message).

    Read with the csv module (no pandas at a run's start), by :func:`column_cells`: blank
    lines only at the ends, a UTF-8 byte-order mark dropped, numbers as Python's float.
    """
    try:
        with path.open(encoding="utf-8-sig", newline="") as stream:
            cells = column_cells(stream, "interarrival_s")
    except (OSError, UnicodeDecodeError) as exc:
        return f"not a readable CSV: {' '.join(str(exc).split())[:120]}"
    if isinstance(cells, str):
        return cells
    lines, text = cells
    times = np.array([_seconds(t) for t in text], dtype=float)
    bad = np.flatnonzero(~np.isfinite(times) | (times < 0) | (times > MAX_INTERARRIVAL_S))
    if bad.size:
        return (f"line {lines[bad[0]]} has inter-arrival time {text[bad[0]][:40]!r}; times "
                f"must be 0 or positive numbers of seconds, at most {MAX_INTERARRIVAL_S:g}")
    if times.size == 0:
        return "has no inter-arrival times"
    if not times.any():
        return f"all {times.size} inter-arrival times are 0; their mean must be positive"
    times.setflags(write=False)
    return times


_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?\Z", re.ASCII)


def _seconds(text: str) -> float:
    """A decimal number as a float; NaN for anything else (words, ``1_000``, ``0x10``, digits
    other than 0-9, which Python's float reads but pandas and ``cell fit`` do not)."""
    return float(text) if _NUMBER.match(text) else math.nan
