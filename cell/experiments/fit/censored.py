"""Times to failure and to repair, some of them right-censored (``cell fit --as
time_to_failure --censored COLUMN``).

A maintenance log ends with machines still running: their times to failure are known only
to exceed the time they were last seen working (right-censored).  Leaving those out, or
counting them as failures, shortens every estimate of life.  The fit here maximises the
censored likelihood, Σ log f(t) over the failures plus Σ log S(t) over the censored times,
with scipy's own machinery: ``scipy.stats.CensoredData`` passed to ``dist.fit``.  The
families are the usual life distributions with their threshold held at 0 (a two-parameter
Weibull, gamma and lognormal, and the exponential), as reliability work fits them; the
goodness of fit is the largest distance D between the fitted cdf and the Kaplan-Meier
estimate (``scipy.stats.ecdf``), which has no simple p-value under censoring.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import stats

from cell.experiments.fit.budget import DEFAULT_BUDGET_S, subsample
from cell.experiments.fit.mle import Fit, family_of, fit_each, moments_of, rank
from cell.scenario.arrivals import param_names

#: The families tried for times to failure or repair (each with loc held at 0).
LIFETIME_FAMILIES: tuple[str, ...] = ("weibull_min", "gamma", "lognorm", "expon")


def censored_loglik(dist: Any, x: NDArray[np.float64], censored: NDArray[np.bool_],
                    theta: Sequence[float]) -> float:
    """Σ log pdf over the observed times plus Σ log sf over the censored ones (-inf if not finite)."""
    with np.errstate(all="ignore"):
        ll = float(np.sum(dist.logpdf(x[~censored], *theta)) + np.sum(dist.logsf(x[censored], *theta)))
    return ll if math.isfinite(ll) else -math.inf


def km_distance(x: NDArray[np.float64], censored: NDArray[np.bool_], cdf: Any) -> float:
    """The largest distance between ``cdf`` (continuous) and the Kaplan-Meier estimate of the
    cdf of ``x``: at its steps, on either side of each (between them the estimate is flat)."""
    km = stats.ecdf(stats.CensoredData.right_censored(x, censored)).cdf
    at = np.asarray(cdf(km.quantiles), dtype=float)
    before = np.concatenate([[0.0], km.probabilities[:-1]])
    return float(max(np.max(np.abs(at - km.probabilities)), np.max(np.abs(at - before))))


def _fit_life(family: str, x: NDArray[np.float64], censored: NDArray[np.bool_]) -> Fit:
    dist = family_of(family)
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        data = stats.CensoredData.right_censored(x, censored) if censored.any() else x
        theta = [float(v) for v in dist.fit(data, floc=0.0)]
        ll = censored_loglik(dist, x, censored, theta)
        if not (np.all(np.isfinite(theta)) and math.isfinite(ll)):
            raise RuntimeError(f"{family}: the fit did not converge")
        if censored.any():
            statistic, p_value = km_distance(x, censored, lambda t: dist.cdf(t, *theta)), math.nan
        else:
            ks = stats.kstest(x, dist.cdf, args=tuple(theta))
            statistic, p_value = float(ks.statistic), float(ks.pvalue)
        params = dict(zip(param_names(dist), theta))
        moments = moments_of(dist(**params))
    return Fit(family, params, statistic, p_value, ll, 2.0 * (len(theta) - 1) - 2.0 * ll, moments)


def fit_lifetimes(values: ArrayLike, censored: ArrayLike | None = None,
                  families: Sequence[str] = LIFETIME_FAMILIES, rank_by: str = "aic",
                  budget_s: float | None = DEFAULT_BUDGET_S) -> list[Fit]:
    """Fit each family to the times ``values`` (``censored`` True where the time is only a
    lower bound: the item was still working) by maximum likelihood with loc = 0, and rank
    them, best first (AIC counts the free parameters only; ``"ks"`` ranks by D).  Each
    within ``budget_s`` seconds; more than
    :data:`~cell.experiments.fit.budget.MAX_FIT_VALUES` times on a seeded subsample."""
    if rank_by not in ("aic", "ks"):
        raise ValueError(f"rank_by must be 'aic' or 'ks', got {rank_by!r}")
    x = np.asarray(values, dtype=float).ravel()
    c = np.zeros(x.size, dtype=bool) if censored is None else np.asarray(censored, dtype=bool).ravel()
    if c.size != x.size:
        raise ValueError("one censoring flag for each time")
    observed = x[~c]
    if observed.size < 2 or not np.all(np.isfinite(x)) or np.ptp(observed) == 0.0:
        raise ValueError("need at least two observed (uncensored) times that are not all equal")
    keep = subsample(np.arange(x.size)).astype(int)
    xs, cs = x[keep], c[keep]
    return rank(fit_each(families, lambda family: _fit_life(family, xs, cs), budget_s), rank_by)
