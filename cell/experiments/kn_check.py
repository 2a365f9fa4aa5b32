"""KN's probability of correct selection, measured: many independent problems (macro-
replications) with a known best, screened at once by :func:`cell.experiments.kn.screen`.

A problem's replication ``r`` of all ``k`` systems comes from ``draw(r)``, an array
(macro, k) with one row per problem (the systems of a row share their random numbers, as
common random numbers make them), the same array whenever asked for the same ``r``.  Each
problem's first stage is judged as :func:`cell.experiments.kn.kn` judges it
(:func:`cell.experiments.kn.first_stage_df`): a problem it refuses counts as refused, not
as a selection.  ``rule=False`` screens as KN without that rule (every first stage worth
n0 - 1 degrees of freedom, none refused), to show what the rule guards against.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from cell.experiments.kn import first_stage_df, h_squared, pair_variances, screen

Draw = Callable[[int], np.ndarray]


@dataclass(frozen=True)
class MacroResult:
    """What ``macro`` problems gave."""

    macro: int
    refused: int
    """Problems whose first stage was refused (a pair's difference never varied)."""
    correct: int
    """Problems not refused that ended with the best alone."""
    unfinished: int
    """Problems not refused that reached the budget with more than one system left: no
    selection (``cell`` reports them as not told apart), so neither right nor wrong."""

    @property
    def decided(self) -> int:
        return self.macro - self.refused - self.unfinished

    @property
    def wrong(self) -> int:
        return self.decided - self.correct

    @property
    def pcs(self) -> float:
        """The share of the problems that ended in a selection that chose the best."""
        return self.correct / self.decided if self.decided else math.nan

    @property
    def se(self) -> float:
        """The standard error of :attr:`pcs` (binomial)."""
        p = self.pcs
        return math.sqrt(p * (1 - p) / self.decided) if self.decided else math.nan


def macro_pcs(draw: Draw, best: int, delta: float, n0: int, pcs: float = 0.95,
              maximize: bool = True, max_n: int = 20000, rule: bool = True) -> MacroResult:
    """KN on every row of ``draw`` at once; ``best`` is the system with the best mean (by at
    least ``delta``, for the guarantee to apply)."""
    sign = 1.0 if maximize else -1.0
    first = np.stack([sign * np.asarray(draw(r), dtype=float) for r in range(n0)], axis=1)
    macro, k = first.shape[0], first.shape[2]
    if rule:
        df = first_stage_df(first)
        refused = df == 0
        table = np.array([h_squared(k, 1 - pcs, n + 1) if n else 0.0 for n in range(n0)])
        h2: float | np.ndarray = table[df][:, None, None]
    else:
        refused = np.zeros(macro, dtype=bool)
        h2 = h_squared(k, 1 - pcs, n0)
    s2 = pair_variances(first)
    sums = first.sum(axis=1)
    alive = np.ones((macro, k), dtype=bool)
    r = n0
    while True:
        alive = screen(sums / r, s2, alive, r, h2, delta)
        single = alive.sum(axis=1) == 1
        if single[~refused].all() or r == max_n:
            break
        sums += sign * np.asarray(draw(r), dtype=float)
        r += 1
    kept = ~refused
    return MacroResult(macro, int(refused.sum()), int((single & alive[:, best] & kept).sum()),
                       int((~single & kept).sum()))


def poisson_draw(means: np.ndarray | list[float], macro: int, seed: int) -> Draw:
    """Independent Poisson counts with these means, a row per problem."""
    lam = np.asarray(means, dtype=float)
    return lambda r: np.random.default_rng((seed, r)).poisson(lam, size=(macro, len(lam)))


def pool_draw(pool: np.ndarray, macro: int, seed: int, common: bool = True) -> Draw:
    """Replications drawn with replacement from ``pool`` (n, k), the pool's means being the
    true means: whole rows, so the systems keep their common random numbers, or with
    ``common=False`` each system's from a row of its own (systems whose counts do not move
    together)."""
    k = pool.shape[1]

    def draw(r: int) -> np.ndarray:
        rng = np.random.default_rng((seed, r))
        if common:
            return pool[rng.integers(len(pool), size=macro)]
        return pool[rng.integers(len(pool), size=(macro, k)), np.arange(k)]

    return draw
