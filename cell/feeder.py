"""The parts supply (thesis §6.2 d, eq. 6.9; SPEC §5).

Inter-arrival times are drawn by inverse cdf: u ~ U(0, 1) from the feeder's own
numpy stream, T = F⁻¹(u) with scipy.stats' ``ppf``.  For the default Weibull
that is literally eq. 6.9, T = 17.6019 + 5.4342 (-ln(1 - u))^0.2038.  The
stream is a child of the run's SeedSequence that nothing else uses, so every
policy run with the same seed sees the same parts (common random numbers).  A
CSV trace of observed times replaces the distribution when given.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.stats
import simpy
from numpy.typing import NDArray

from cell.scenario import Arrivals, read_trace

#: The feeder's child stream of the root SeedSequence (other streams take other keys).
FEEDER_STREAM = 0


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


def interarrival_times(arrivals: Arrivals, n: int, seed: int | np.random.SeedSequence,
                       base_dir: Path | str = ".") -> NDArray[np.float64]:
    """The first ``n`` inter-arrival times (s) of a run: eq. 6.9 by default.

    With ``arrivals.trace_csv`` the trace's times are used in order, repeating
    from its start if the run needs more than it holds.
    """
    if arrivals.trace_csv is not None:
        trace = read_trace(Path(base_dir) / arrivals.trace_csv)
        return np.resize(trace, n).astype(float)
    u = stream(seed, FEEDER_STREAM).random(n)
    dist = getattr(scipy.stats, arrivals.distribution)
    return np.asarray(dist.ppf(u, **arrivals.params), dtype=float)


class Feeder:
    """Drops part i on the input conveyor T_i after part i - 1 (SimPy process)."""

    def __init__(self, env: simpy.Environment, interarrival_s: NDArray[np.float64],
                 conveyor: object, n_parts: int):
        self.env = env
        self.interarrival_s = interarrival_s
        """All the run's draws; the one after the last part is the controller's look-ahead."""
        self.fed_s = np.cumsum(interarrival_s).tolist()
        """When each part is (or would be) dropped: the upstream process's schedule."""
        self.n_parts = n_parts
        self.conveyor = conveyor
        self.process = env.process(self.run())

    def run(self):  # noqa: ANN201 (SimPy generator)
        env, drop = self.env, self.conveyor.drop
        for i in range(self.n_parts):
            yield env.timeout(self.fed_s[i] - env.now)
            drop(i)
