"""Statistics for replicated experiments: confidence intervals, paired
differences, a replications-to-precision stopping rule (MSER warm-up detection is
:mod:`cell.sim.warmup`).

Pure functions over numpy arrays; the distributions and intervals come from
``scipy.stats``, imported only where an interval is computed, so a run whose
warm-up is found by MSER (``run.warmup_parts: auto``) starts without scipy.
NaNs are dropped before any computation (pairwise for paired data), so a
failed replication recorded as NaN does not poison a summary.
"""

from __future__ import annotations

import math
from collections.abc import Hashable, Mapping, Sequence
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

K = TypeVar("K", bound=Hashable)

SUMMARY_KEYS = ("n", "mean", "sd", "ci_low", "ci_high", "run_p2_5", "run_p97_5")
PAIRED_KEYS = ("n", "mean", "sd", "ci_low", "ci_high", "p_value")


def _clean(x: ArrayLike) -> NDArray[np.float64]:
    """``x`` as a flat float array without NaNs."""
    a: NDArray[np.float64] = np.asarray(x, dtype=np.float64).ravel()
    return a[~np.isnan(a)]


def _check_confidence(confidence: float) -> None:
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must be in (0, 1), got {confidence!r}")


def no_variation(x: ArrayLike) -> bool:
    """True when there are at least two values (NaNs dropped) and their sample
    standard deviation is 0: all equal (or spread so little its square underflows).

    A report should then say "no variation between replications" rather than
    print a zero-width interval.  For paired data pass ``a - b``.
    """
    a = _clean(x)
    return a.size >= 2 and _mean_sd(a)[1] == 0.0


def _mean_sd(a: NDArray[np.float64]) -> tuple[float, float]:
    """Mean and sample standard deviation (ddof 1) of two or more values.  All equal:
    the value itself and 0, exactly -- numpy's mean of equal values can be off by a
    rounding, which would leave an sd of about 1e-16 of them, not a spread."""
    if np.all(a == a[0]):
        return float(a[0]), 0.0
    return float(np.mean(a)), float(np.std(a, ddof=1))


def summarise(x: ArrayLike, confidence: float = 0.95,
              _ends: tuple[float, float] | None = None) -> dict[str, float]:
    """Mean with a Student-t confidence interval, and where one single run falls.

    Keys: ``n, mean, sd, ci_low, ci_high, run_p2_5, run_p97_5``.  ``sd`` is the
    sample standard deviation (ddof 1); the interval is
    mean ± t(1 - (1 - confidence)/2, n - 1) · sd/√n.  ``run_p2_5``/``run_p97_5``
    are the 2.5 and 97.5 percentiles of the values themselves (numpy's linear
    interpolation), the range of a single replication, not of the mean.

    n = 0: everything NaN.  n = 1: sd and the interval NaN.  No variation: the
    interval is [mean, mean]; values all equal give that value and sd 0 exactly
    (see :func:`no_variation`).
    """
    _check_confidence(confidence)
    a = _clean(x)
    n = a.size
    nan = math.nan
    if n == 0:
        return dict.fromkeys(SUMMARY_KEYS, nan) | {"n": 0}
    p_lo, p_hi = _ends or tuple(float(v) for v in np.percentile(a, [2.5, 97.5]))
    if n == 1:
        return {"n": 1, "mean": float(a[0]), "sd": nan, "ci_low": nan, "ci_high": nan,
                "run_p2_5": p_lo, "run_p97_5": p_hi}
    mean, sd = _mean_sd(a)
    if sd == 0.0:  # no variation
        lo = hi = mean
    else:
        from scipy import stats

        lo, hi = (float(v) for v in stats.t.interval(confidence, df=n - 1, loc=mean,
                                                       scale=sd / math.sqrt(n)))
    return {"n": n, "mean": mean, "sd": sd, "ci_low": lo, "ci_high": hi,
            "run_p2_5": p_lo, "run_p97_5": p_hi}


def summarise_many(arrays: Sequence[ArrayLike], confidence: float = 0.95) -> list[dict[str, float]]:
    """:func:`summarise` of each array, the same figures bit for bit, with the single runs'
    percentiles of all arrays of one length taken in one numpy call and the t intervals of
    all in one scipy call: one call of each per point and measure was what a sweep's
    ``summary.csv`` spent its time on (12.8 ms of CPU a point of 41 measures, now 1.5;
    ``cell bench``, ``sweep_overhead_ms_per_point``)."""
    _check_confidence(confidence)
    clean = [_clean(x) for x in arrays]
    by_n: dict[int, list[int]] = {}
    for i, a in enumerate(clean):
        by_n.setdefault(a.size, []).append(i)
    ends: dict[int, tuple[float, float]] = {}
    for n, which in by_n.items():
        if n == 0:
            continue
        p = np.percentile(np.stack([clean[i] for i in which]), [2.5, 97.5], axis=1)
        ends.update((i, (float(p[0, j]), float(p[1, j]))) for j, i in enumerate(which))
    out = [summarise(a, confidence, ends.get(i)) if a.size < 2 or _mean_sd(a)[1] == 0.0
           else None for i, a in enumerate(clean)]  # those without a t interval
    spread = [i for i, o in enumerate(out) if o is None]
    if spread:
        from scipy import stats

        moments = [_mean_sd(clean[i]) for i in spread]
        sizes = [clean[i].size for i in spread]
        lo, hi = (np.asarray(v, dtype=float).ravel() for v in stats.t.interval(
            confidence, df=np.array(sizes) - 1, loc=np.array([m for m, _ in moments]),
            scale=np.array([sd / math.sqrt(k) for (_, sd), k in zip(moments, sizes, strict=True)])))
        for j, i in enumerate(spread):
            mean, sd = moments[j]
            out[i] = {"n": sizes[j], "mean": mean, "sd": sd, "ci_low": float(lo[j]),
                      "ci_high": float(hi[j]), "run_p2_5": ends[i][0], "run_p97_5": ends[i][1]}
    return [o for o in out if o is not None]


def paired_difference(a: ArrayLike, b: ArrayLike, confidence: float = 0.95) -> dict[str, float]:
    """The mean paired difference a − b with its t interval and two-sided p-value.

    For runs under common random numbers (replication i of ``a`` and of ``b``
    share their random streams).  Keys: ``n, mean, sd, ci_low, ci_high, p_value``
    (``scipy.stats.ttest_rel``).  Pairs with a NaN on either side are dropped.
    Differences all equal give that difference, sd 0 and interval [mean, mean]
    exactly, and a NaN p-value: check ``no_variation(a - b)``.  n < 2: sd,
    interval and p-value NaN.
    """
    _check_confidence(confidence)
    x, y = np.asarray(a, dtype=float).ravel(), np.asarray(b, dtype=float).ravel()
    if x.shape != y.shape:
        raise ValueError(f"paired samples differ in length: {x.size} and {y.size}")
    keep = ~(np.isnan(x) | np.isnan(y))
    x, y = x[keep], y[keep]
    d = x - y
    n = d.size
    nan = math.nan
    if n < 2:
        mean = float(d[0]) if n else nan
        return {"n": n, "mean": mean, "sd": nan, "ci_low": nan, "ci_high": nan, "p_value": nan}
    mean, sd = _mean_sd(d)
    if sd == 0.0:  # no variation
        return {"n": n, "mean": mean, "sd": sd, "ci_low": mean, "ci_high": mean, "p_value": nan}
    from scipy import stats

    res = stats.ttest_rel(x, y)
    ci = res.confidence_interval(confidence)
    return {"n": n, "mean": mean, "sd": sd, "ci_low": float(ci.low), "ci_high": float(ci.high),
            "p_value": float(res.pvalue)}


def paired_many(pairs: Sequence[tuple[ArrayLike, ArrayLike]], confidence: float = 0.95
                ) -> list[dict[str, float]]:
    """:func:`paired_difference` of each pair, the same figures bit for bit, with the t-tests
    of all pairs of one length run as one ``scipy.stats.ttest_rel`` over rows (one call
    of it per pair was most of a sweep's ``differences.csv``: 13.1 ms of CPU a point of 41
    measures, now 1.1; ``cell bench``, ``sweep_overhead_ms_per_point``)."""
    _check_confidence(confidence)
    out: list[dict[str, float] | None] = []
    rows: dict[int, list[tuple[int, NDArray[np.float64], NDArray[np.float64]]]] = {}
    for i, (a, b) in enumerate(pairs):
        x, y = np.asarray(a, dtype=float).ravel(), np.asarray(b, dtype=float).ravel()
        if x.shape != y.shape:
            raise ValueError(f"paired samples differ in length: {x.size} and {y.size}")
        keep = ~(np.isnan(x) | np.isnan(y))
        x, y = x[keep], y[keep]
        if x.size < 2 or _mean_sd(x - y)[1] == 0.0:
            out.append(paired_difference(x, y, confidence))  # no t-test there
        else:
            out.append(None)
            rows.setdefault(x.size, []).append((i, x, y))
    if rows:
        from scipy import stats

        for group in rows.values():
            res = stats.ttest_rel(np.stack([g[1] for g in group]),
                                  np.stack([g[2] for g in group]), axis=1)
            ci = res.confidence_interval(confidence)
            low, high, p = (np.asarray(v).ravel() for v in (ci.low, ci.high, res.pvalue))
            for j, (i, x, y) in enumerate(group):
                mean, sd = _mean_sd(x - y)
                out[i] = {"n": x.size, "mean": mean, "sd": sd, "ci_low": float(low[j]),
                          "ci_high": float(high[j]), "p_value": float(p[j])}
    return [o for o in out if o is not None]


def relative_half_width(x: ArrayLike, confidence: float = 0.95) -> float:
    """The confidence interval's half-width divided by |mean|.

    0 with no variation; inf when the mean is 0 but the half-width is not, and
    when there are fewer than two values (precision not yet known).
    """
    s = summarise(x, confidence)
    if s["n"] < 2:
        return math.inf
    half = (s["ci_high"] - s["ci_low"]) / 2.0
    if half == 0.0:
        return 0.0
    if s["mean"] == 0.0:
        return math.inf
    return float(half / abs(s["mean"]))


# --------------------------------------------------------------------------- replications to precision
def precision_reached(values_by_point: Mapping[K, ArrayLike], precision: float,
                      confidence: float = 0.95, min_n: int = 10) -> dict[K, bool]:
    """Per grid point: have its replications reached the precision asked for?

    A point is done when it has at least ``min_n`` values (NaNs not counted) and
    its confidence half-width is at most ``precision`` × |mean| (see
    :func:`relative_half_width`).  Each point is judged on its own values only,
    so the answer is a function of the data alone: evaluate it after whole
    rounds (all of a round's replications in, kept in replication order) and it
    does not depend on how many workers ran them or in what order they finished.

    Stopping when the interval first looks narrow enough makes the final
    interval's coverage only approximately the nominal ``confidence`` (slightly
    below it for small ``min_n``); a larger ``min_n`` keeps the gap small.
    """
    if not precision > 0.0:
        raise ValueError(f"precision must be > 0, got {precision!r}")
    if min_n < 2:
        raise ValueError(f"min_n must be at least 2, got {min_n!r}")
    _check_confidence(confidence)
    out: dict[K, bool] = {}
    for key, values in values_by_point.items():
        a = _clean(values)
        out[key] = a.size >= min_n and relative_half_width(a, confidence) <= precision
    return out


def next_round(counts: Mapping[K, int], reached: Mapping[K, bool], batch: int,
               max_n: int) -> dict[K, int]:
    """Replications each point still needs in the next round.

    0 for a point that has reached its precision or already has ``max_n``;
    otherwise ``batch``, cut so the point never exceeds ``max_n``.  The
    experiment is over when every value is 0.
    """
    if batch < 1:
        raise ValueError(f"batch must be at least 1, got {batch!r}")
    if max_n < 1:
        raise ValueError(f"max_n must be at least 1, got {max_n!r}")
    return {key: 0 if reached.get(key, False) else max(0, min(batch, max_n - n))
            for key, n in counts.items()}
