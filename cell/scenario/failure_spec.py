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

#: Pieces of equipment that can fail, in the order states.csv lists them.
EQUIPMENT = ("robot", "input_belt", "output_belt", "sensor")
#: The child streams of the run's root SeedSequence: (time to failure, time to repair) per
#: equipment.  The feeder's is 0 and the wear clock's 21; these keep clear of both.
STREAM_KEYS = {name: (2100 + 2 * i, 2101 + 2 * i) for i, name in enumerate(EQUIPMENT)}
#: Draws made per ``ppf`` call.
BLOCK = 256
SECONDS_PER_HOUR = 3600.0


def check_failures(f: Any, file: object) -> None:
    """Refuse times that scipy rejects, can be negative, or have no finite positive mean,
    and planned stops longer than their interval."""
    if f is None:
        return
    for name in EQUIPMENT:
        mode = getattr(f, name)
        if mode is None:
            continue
        for which in ("time_to_failure", "time_to_repair"):
            check_time(getattr(mode, which), f"failures.{name}.{which}", file)
    m = f.maintenance
    if m is not None:
        if m.duration_min * 60.0 >= m.every_h * SECONDS_PER_HOUR:
            raise ScenarioError(file, "failures.maintenance.duration_min", m.duration_min,
                                f"a planned stop must be shorter than its interval "
                                f"(failures.maintenance.every_h = {m.every_h:g} h)")


def frozen(spec: Any) -> Any:
    """The scipy.stats distribution of a ``{distribution, params}`` setting."""
    import scipy.stats

    return getattr(scipy.stats, spec.distribution)(**dict(spec.params))


def check_time(spec: Any, key: str, file: object) -> float:
    """A time distribution's mean, after refusing what cannot be one."""
    import scipy.stats

    dist = getattr(scipy.stats, spec.distribution, None)
    if not isinstance(dist, scipy.stats.rv_continuous):
        raise ScenarioError(file, f"{key}.distribution", spec.distribution,
                            "not a continuous distribution in scipy.stats")
    try:
        d = frozen(spec)
        mean, low = float(d.mean()), float(d.support()[0])
    except (TypeError, ValueError) as exc:
        raise ScenarioError(file, f"{key}.params", dict(spec.params),
                            f"not accepted by scipy.stats.{spec.distribution}: {exc}") from None
    if math.isnan(mean) and math.isnan(low):  # scipy's answer for parameters out of range
        raise ScenarioError(file, f"{key}.params", dict(spec.params),
                            f"scipy.stats.{spec.distribution} takes no such parameters (a zero "
                            "or negative scale?): the mean time would be undefined")
    if not math.isfinite(mean):  # infinite, or undefined (a Cauchy's)
        raise ScenarioError(file, f"{key}.params", dict(spec.params),
                            f"scipy.stats.{spec.distribution} with these has no finite mean")
    if not low >= 0 or not mean > 0:
        raise ScenarioError(file, f"{key}.params", dict(spec.params),
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
