"""Selection of the best system: Kim & Nelson's fully sequential procedure KN.

S.-H. Kim and B. L. Nelson (2001), "A fully sequential procedure for indifference-zone
selection in simulation", ACM TOMACS 11(3), 251-273.  Read beside TomMonks/sim-tools
(``sim_tools/ovs/indifference_zone.py``, MIT); written here afresh, in numpy only.

``k`` systems are sampled in pairs: replication ``r`` of every system sees the same random
numbers (common random numbers), which KN allows and which shrinks the variances of the
differences it screens on.  With ``n0`` first-stage replications, an indifference zone ``δ``
and a probability of correct selection ``1 - α`` (for the largest mean):

- η = ½ [(2α / (k - 1))^(-2 / (n0 - 1)) - 1],  h² = 2η (n0 - 1);
- S²_il: the sample variance of X_i - X_l over the first ``n0`` replications;
- at stage r ≥ n0, system i stays if X̄_i(r) ≥ X̄_l(r) - W_il(r) for every other survivor
  l, W_il(r) = max(0, δ / (2r) · (h² S²_il / δ² - r));
- one more replication of each survivor, until one is left.

If the best mean is at least δ above every other, the survivor is the best with probability
at least 1 - α; otherwise it is within δ of the best with that probability.  A budget
``max_n`` stops the procedure early; the survivors left then cannot be told apart.

:func:`screen` is the elimination step, vectorised over any leading axes (so 1,000
macro-replications run at once in a test); :func:`kn` drives it for one problem, asking
``sample`` for each stage's observations of the survivors only.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

#: Sample(systems, replication) -> the observation of each of those systems at that replication.
Sample = Callable[[Sequence[int], int], Sequence[float]]


def eta(k: int, alpha: float, n0: int) -> float:
    """KN's η for ``k`` systems, error ``alpha`` and ``n0`` first-stage replications."""
    if k < 2 or n0 < 2 or not 0 < alpha < 1:
        raise ValueError(f"KN needs k >= 2, n0 >= 2, 0 < alpha < 1 (k={k}, n0={n0}, alpha={alpha})")
    return 0.5 * ((2 * alpha / (k - 1)) ** (-2 / (n0 - 1)) - 1)


def h_squared(k: int, alpha: float, n0: int) -> float:
    return 2 * eta(k, alpha, n0) * (n0 - 1)


def pair_variances(first: np.ndarray) -> np.ndarray:
    """S²_il of the first stage: ``first`` is (..., n0, k); the result (..., k, k)."""
    diff = first[..., :, :, None] - first[..., :, None, :]
    return np.asarray(diff.var(axis=-3, ddof=1))


def screen(means: np.ndarray, s2: np.ndarray, alive: np.ndarray, r: int, h2: float,
           delta: float) -> np.ndarray:
    """Who survives stage ``r``: ``means`` (..., k) after r replications, ``s2`` (..., k, k),
    ``alive`` (..., k) booleans; larger is better."""
    w = np.maximum(0.0, delta / (2 * r) * (h2 * s2 / delta ** 2 - r))
    beaten = (means[..., :, None] < means[..., None, :] - w) & alive[..., None, :]
    return alive & ~beaten.any(axis=-1)


@dataclass(frozen=True)
class Selection:
    """What KN chose, and on how many replications."""

    best: int
    """The chosen system (the survivor; with several left at ``max_n``, the best mean)."""
    survivors: tuple[int, ...]
    """The systems not eliminated when the procedure stopped (just ``best`` unless the
    budget ran out first: then these cannot be told apart at this δ)."""
    means: tuple[float, ...]
    """Each system's mean over the replications it got (in the measure's own sign)."""
    counts: tuple[int, ...]
    """Replications each system got."""
    delta: float
    pcs: float

    def within_delta(self) -> tuple[int, ...]:
        """The other systems whose mean is within δ of the chosen one's: the guarantee
        does not tell them from it (it is about the best by at least δ)."""
        m = self.means[self.best]
        return tuple(i for i, x in enumerate(self.means)
                     if i != self.best and abs(x - m) < self.delta)

    def alike(self) -> tuple[int, ...]:
        """Those that cannot be told apart from the chosen one: still surviving, or
        within δ of it."""
        return tuple(sorted({*self.survivors, *self.within_delta()} - {self.best}))


def kn(sample: Sample, k: int, delta: float, pcs: float = 0.95, n0: int = 10,
       maximize: bool = True, max_n: int = 1000) -> Selection:
    """Kim & Nelson's KN over ``k`` systems, replication ``r`` of each from ``sample``."""
    if delta <= 0 or not 0 < pcs < 1 or n0 < 2 or max_n < n0:
        raise ValueError(f"KN needs delta > 0, 0 < pcs < 1, 2 <= n0 <= max_n "
                         f"(delta={delta}, pcs={pcs}, n0={n0}, max_n={max_n})")
    sign = 1.0 if maximize else -1.0
    every = list(range(k))
    obs = np.full((max_n, k), np.nan)
    for r in range(n0):
        obs[r] = sample(every, r)
    if k == 1:
        return Selection(0, (0,), (float(obs[:n0, 0].mean()),), (n0,), delta, pcs)
    s2 = pair_variances(sign * obs[:n0])
    h2 = h_squared(k, 1 - pcs, n0)
    alive = np.ones(k, dtype=bool)
    counts = np.full(k, n0)
    r = n0
    while True:
        means = sign * obs[:r].sum(axis=0) / r
        alive = screen(means, s2, alive, r, h2, delta)
        live = np.flatnonzero(alive)
        if len(live) == 1 or r == max_n or _all_tied(s2, live):
            break
        obs[r, live] = sample(live.tolist(), r)
        counts[live] += 1
        r += 1
    final = np.array([obs[:counts[i], i].mean() for i in every])
    best = int(live[np.argmax(sign * final[live])])
    return Selection(best, tuple(int(i) for i in live), tuple(float(x) for x in final),
                     tuple(int(n) for n in counts), delta, pcs)


def _all_tied(s2: np.ndarray, live: np.ndarray) -> bool:
    """Whether the survivors' differences had no variance at all: equal under common random
    numbers (a count that is 0 for all), so that no replication would ever part them."""
    sub = s2[np.ix_(live, live)]
    return bool(np.all(sub == 0))
