"""The parts supply's numbers: inter-arrival times (thesis §6.2 d, eq. 6.9).

Times are drawn by inverse cdf: u ~ U(0, 1) from the feeder's own numpy stream,
T = F⁻¹(u) with scipy.stats' ``ppf``.  For the default Weibull that is eq. 6.9,
T = 17.6019 + 5.4342 (-ln(1 - u))^0.2038.  The stream is a child of the run's
SeedSequence that nothing else uses, so every policy run with the same seed sees
the same parts (common random numbers).  A CSV trace of observed times replaces
the distribution when given.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from cell.cache import file_key, memo
from cell.errors import ScenarioError

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
    from its start if the run needs more than it holds.
    """
    if arrivals.trace_csv is not None:
        trace = read_trace(Path(base_dir) / arrivals.trace_csv)
        return np.resize(trace, n).astype(float)
    u = stream(seed, FEEDER_STREAM).random(n)
    return np.asarray(_frozen(arrivals).ppf(u), dtype=float)


def _frozen(arrivals: ArrivalSpec) -> Any:
    import scipy.stats

    return getattr(scipy.stats, arrivals.distribution)(**arrivals.params)


def mean_interarrival(arrivals: ArrivalSpec, base_dir: Path | str = ".") -> float:
    """The mean inter-arrival time (s): the distribution's, or the trace's."""
    if arrivals.trace_csv is not None:
        return float(np.mean(read_trace(Path(base_dir) / arrivals.trace_csv)))
    return float(_frozen(arrivals).mean())


def check_arrivals(arrivals: ArrivalSpec, base_dir: Path, file: object) -> None:
    """Refuse a distribution scipy does not have, parameters it rejects, times that
    can be negative or have no finite mean, and an unusable trace."""
    import scipy.stats

    dist = getattr(scipy.stats, arrivals.distribution, None)
    if not isinstance(dist, scipy.stats.rv_continuous):
        raise ScenarioError(file, "arrivals.distribution", arrivals.distribution,
                            "not a continuous distribution in scipy.stats")
    if arrivals.trace_csv is not None:
        path = base_dir / arrivals.trace_csv
        if not path.is_file():
            raise ScenarioError(file, "arrivals.trace_csv", str(path), "no such file")
        read_trace(path, file)
        return
    params = dict(arrivals.params)
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
                            f"the mean inter-arrival time would be {mean:.4g} s; at most "
                            f"{MAX_INTERARRIVAL_S:g} s")


def read_trace(path: Path, file: object = None) -> NDArray[np.float64]:
    """Inter-arrival times from a CSV trace: one column ``interarrival_s``, all > 0.

    Parsed once per version of the file (path, size, modification time), so a
    sweep's replications do not read it again.  The array is read-only.
    """
    if not path.is_file():
        raise ScenarioError(file or path, "arrivals.trace_csv", str(path), "no such file")
    times = _parse_trace(path)
    if isinstance(times, str):
        raise ScenarioError(file or path, "arrivals.trace_csv", str(path), times)
    return times


@memo(key=lambda path: file_key(path))
def _parse_trace(path: Path) -> Any:
    """The trace's times, or why they cannot be used (a message)."""
    import pandas as pd

    try:
        frame = pd.read_csv(path, dtype=str, keep_default_na=False, encoding="utf-8")
    except Exception as exc:  # noqa: BLE001 - pandas and the decoder raise many kinds
        return f"not a readable CSV: {' '.join(str(exc).split())[:120]}"
    if "interarrival_s" not in frame.columns:
        return "needs a column named interarrival_s"
    text = frame["interarrival_s"].str.strip()
    times = pd.to_numeric(text, errors="coerce").to_numpy(dtype=float)
    bad = np.flatnonzero(~np.isfinite(times) | (times <= 0) | (times > MAX_INTERARRIVAL_S))
    if bad.size:
        return (f"row {bad[0] + 1} has inter-arrival time {text.iloc[bad[0]][:40]!r}; times "
                f"must be positive numbers of seconds, at most {MAX_INTERARRIVAL_S:g}")
    if times.size == 0:
        return "has no inter-arrival times"
    times.setflags(write=False)
    return times
