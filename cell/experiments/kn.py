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

KN assumes normal observations: S²_il is then never 0 and is as sure as its n0 - 1 degrees
of freedom make it, which is what h² is worked out for.  A count (parts missed, mostly 0)
breaks that.  Two systems' first-stage difference is often the same in every replication:
S²_il = 0, W_il = 0, and KN eliminates on the first difference, whichever system it falls
on.  And a difference that departs from its most common value in only m of the n0
replications gives an S²_il that is a count of m rare events: its relative spread is about
1/√m, that of a normal sample variance on 2m degrees of freedom (a χ²_ν/ν has variance 2/ν),
however large n0 is.  So (:func:`first_stage_df`): a first stage in which some pair's
difference never varies is refused (:class:`FlatFirstStage`); otherwise h² is worked out for
ν = min(n0 - 1, 2 m) degrees of freedom, m the fewest departures of any pair, as if the first
stage were ν + 1 replications long.  A measure that varies continuously has m = n0 - 1 and
is screened as KN has it.  ``make kn-check`` measures the probability of correct selection
on counts with and without the rule (reports/kn/).

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


def screen(means: np.ndarray, s2: np.ndarray, alive: np.ndarray, r: int,
           h2: float | np.ndarray, delta: float) -> np.ndarray:
    """Who survives stage ``r``: ``means`` (..., k) after r replications, ``s2`` (..., k, k),
    ``alive`` (..., k) booleans, ``h2`` a number or (..., 1, 1); larger is better."""
    w = np.maximum(0.0, delta / (2 * r) * (h2 * s2 / delta ** 2 - r))
    beaten = (means[..., :, None] < means[..., None, :] - w) & alive[..., None, :]
    return alive & ~beaten.any(axis=-1)


def departures(first: np.ndarray) -> np.ndarray:
    """m_il: in how many of the first stage's replications the difference X_i - X_l is not
    its most common value; ``first`` is (..., n0, k), the result (..., k, k), n0 on the
    diagonal.  n0 - 1 when no value repeats (a measure that varies continuously)."""
    n0, k = first.shape[-2], first.shape[-1]
    diff = first[..., :, :, None] - first[..., :, None, :]  # (..., n0, k, k)
    same = (diff[..., :, None, :, :] == diff[..., None, :, :, :]).sum(axis=-3)
    m = n0 - same.max(axis=-3)
    return np.where(np.eye(k, dtype=bool), n0, m)


def first_stage_df(first: np.ndarray) -> np.ndarray:
    """The degrees of freedom the first stage's variances are worth, ν = min(n0 - 1, 2 m)
    with m the fewest :func:`departures` of any pair: (...,) for ``first`` (..., n0, k).
    0 means some pair's difference never varied: KN cannot screen it."""
    n0 = first.shape[-2]
    return np.minimum(n0 - 1, 2 * departures(first).min(axis=(-2, -1)))


class FlatFirstStage(ValueError):
    """Systems ``i`` and ``l`` differ by the same amount in all ``n0`` first-stage replications."""

    def __init__(self, i: int, l: int, n0: int):
        self.i, self.l, self.n0 = i, l, n0
        super().__init__(f"systems {i} and {l} differ by the same amount in all {n0} "
                         "first-stage replications")


class NotANumber(ValueError):
    """An observation is NaN or infinite: system ``i``, replication ``r``."""

    def __init__(self, i: int, r: int, value: float):
        self.i, self.r, self.value = i, r, value
        super().__init__(f"system {i}, replication {r}: {value}")


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
    if not 0 < delta < np.inf or not 0 < pcs < 1 or n0 < 2 or max_n < n0:
        raise ValueError(f"KN needs delta > 0, 0 < pcs < 1, 2 <= n0 <= max_n "
                         f"(delta={delta}, pcs={pcs}, n0={n0}, max_n={max_n})")
    sign = 1.0 if maximize else -1.0
    every = list(range(k))
    obs = np.full((max_n, k), np.nan)
    for r in range(n0):
        obs[r] = _finite(sample(every, r), every, r)
    if k == 1:
        return Selection(0, (0,), (float(obs[:n0, 0].mean()),), (n0,), delta, pcs)
    df = int(first_stage_df(obs[:n0]))
    if df == 0:
        i, l = (int(v) for v in np.argwhere(departures(obs[:n0]) == 0)[0])
        raise FlatFirstStage(i, l, n0)
    s2 = pair_variances(sign * obs[:n0])
    h2 = h_squared(k, 1 - pcs, df + 1)
    alive = np.ones(k, dtype=bool)
    counts = np.full(k, n0)
    r = n0
    while True:
        means = sign * obs[:r].sum(axis=0) / r
        alive = screen(means, s2, alive, r, h2, delta)
        live = np.flatnonzero(alive)
        if len(live) == 1 or r == max_n:
            break
        obs[r, live] = _finite(sample(live.tolist(), r), live.tolist(), r)
        counts[live] += 1
        r += 1
    final = np.array([obs[:counts[i], i].mean() for i in every])
    best = int(live[np.argmax(sign * final[live])])
    return Selection(best, tuple(int(i) for i in live), tuple(float(x) for x in final),
                     tuple(int(n) for n in counts), delta, pcs)


def _finite(values: Sequence[float], systems: Sequence[int], r: int) -> np.ndarray:
    x = np.asarray(values, dtype=float)
    bad = np.flatnonzero(~np.isfinite(x))
    if len(bad):
        raise NotANumber(systems[bad[0]], r, float(x[bad[0]]))
    return x
