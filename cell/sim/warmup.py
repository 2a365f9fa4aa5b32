"""A run's warm-up: MSER truncation of its leading observations (White 1997),
which ``run.warmup_parts: auto`` uses to cut a run's transient."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def mser_statistic(x: ArrayLike, batch: int = 5) -> NDArray[np.float64]:
    """MSER(d) for d = 0, 1, ... batches deleted, over the first half of the batches.

    With Z_1..Z_k the means of consecutive batches of ``batch`` observations (an
    incomplete last batch is ignored) and Z̄(d) the mean of Z_{d+1}..Z_k,
    MSER(d) = Σ_{j>d} (Z_j − Z̄(d))² / (k − d)²  (White 1997), i.e. the variance of
    the remaining batch means over their number (with divisor k − d; the sample
    variance's k − d − 1 chose the same d on every test series we tried).
    """
    if batch < 1:
        raise ValueError(f"batch must be at least 1, got {batch!r}")
    a = np.asarray(x, dtype=float).ravel()
    if not np.all(np.isfinite(a)):
        raise ValueError("the series for MSER must be finite (no NaN or inf)")
    k = a.size // batch
    if k < 3:
        return np.zeros(1)
    z = a[:k * batch].reshape(k, batch).mean(axis=1)
    last = min(k // 2, k - 2)  # keep at least two batches
    # Sums over the tail z[d:], for every d at once.
    tail_n = np.arange(k, 0, -1, dtype=float)
    tail_sum = np.cumsum(z[::-1])[::-1]
    tail_sq = np.cumsum((z - z.mean())[::-1] ** 2)[::-1]  # centred for accuracy
    tail_mean_c = tail_sum / tail_n - z.mean()
    ss = np.maximum(tail_sq - tail_n * tail_mean_c ** 2, 0.0)
    out: NDArray[np.float64] = (ss / tail_n ** 2)[: last + 1]
    return out


def mser(x: ArrayLike, batch: int = 5) -> int:
    """Warm-up truncation point, in observations (a multiple of ``batch``), by MSER.

    The number of leading observations to delete: ``batch`` × the d that
    minimises :func:`mser_statistic`, searched over the first half of the
    batches only (the usual rule: a minimum in the second half means the
    series is too short).  Ties go to the smaller d.  Series shorter than three
    batches give 0.  A result near half the series is a warning that the run
    is too short to have left its transient.

    White, K. P. (1997) "An effective truncation heuristic for bias reduction in
    simulation output", Simulation 69(6); White, Cobb & Spratt (2000) "A
    comparison of five steady-state truncation heuristics for simulation",
    Proc. Winter Simulation Conference.
    """
    return int(np.argmin(mser_statistic(x, batch))) * batch


def mser5(x: ArrayLike) -> int:
    """MSER-5: :func:`mser` with batches of five observations (White et al. 2000)."""
    return mser(x, batch=5)
