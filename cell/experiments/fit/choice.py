"""Which fit ``cell fit`` writes, and the caution when it does not stand for the data.

A fit is written only when a scenario accepts it (:func:`unusable`: no negative times, a
finite positive mean, a defined support), and of those the ranking's best unless it misses the
data's mean or sd (:func:`choose`); a written fit whose mean or sd is more than 10 % off the
data's, or that the KS test rejects, carries a caution (:func:`caution`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import stats

from cell.experiments.fit.mle import Fit
from cell.scenario.arrivals import MAX_INTERARRIVAL_S

#: A KS p-value below this rejects a fit (the p-value is optimistic, so this is lenient).
P_FLOOR = 1e-3
#: A fit's mean (sd) is off the data's when it differs by more than this fraction of it and by
#: more than twice the data's own sampling error of it (so a small sample's noise is no alarm).
MEAN_TOLERANCE, SD_TOLERANCE = 0.05, 0.10
#: A written fit whose mean or sd is more than this fraction off the data's gets a caution,
#: whatever the sample's own sampling error (which the caution then names).
CAUTION_OFF = 0.10


def unusable(fit: Fit, most_mean: float = MAX_INTERARRIVAL_S) -> str:
    """Why a scenario would refuse ``fit`` as a time's distribution, or "" when it accepts it:
    a parameter not finite, a support scipy cannot say (NaN, as ``truncpareto`` gives for
    some fits), negative times, no finite mean (``halfcauchy``, ``levy``), a mean not positive
    or above ``most_mean`` seconds (the rules of :func:`cell.scenario.arrivals.check_arrivals`)."""
    if not all(math.isfinite(v) for v in fit.params.values()):
        return "a parameter is not finite"
    try:
        low, high = (float(v) for v in fit.frozen().support())
    except (ValueError, TypeError):
        return "scipy refuses its parameters"
    if math.isnan(low) or math.isnan(high):
        return "its support is not defined (NaN)"
    if low < 0.0:
        return "allows negative times"
    mean = fit.fitted_moments()[0]
    if not math.isfinite(mean):
        return "no finite mean"
    if not mean > 0.0:
        return "its mean is not positive"
    if mean > most_mean:
        return f"its mean ({mean:.4g} s) is beyond {most_mean:g} s"
    return ""


class _Moments(NamedTuple):
    """A fit's mean and sd beside the data's, and whether each is off (:data:`MEAN_TOLERANCE`)."""

    fit_mean: float
    fit_sd: float
    mean: float
    sd: float
    mean_off: bool
    sd_off: bool

    @property
    def sd_error(self) -> float:
        """The fit's sd off the data's, as a fraction of the data's (inf if it has none)."""
        error = abs(self.fit_sd / self.sd - 1.0)
        return error if math.isfinite(error) else math.inf


def _moments(fit: Fit, x: NDArray[np.float64]) -> _Moments:
    """The sd's sampling error takes the larger kurtosis of the data's and the fit's: a
    heavy-tailed sample rarely shows its tail, so its own kurtosis is too small."""
    mean, sd = float(x.mean()), float(x.std(ddof=1))
    fit_mean, fit_sd, fit_excess = fit.fitted_moments()
    fit_kurtosis = fit_excess + 3.0 if not math.isnan(fit_excess) else 0.0
    kurtosis = max(float(stats.kurtosis(x, fisher=False)), fit_kurtosis)
    mean_ok = abs(fit_mean - mean) <= max(MEAN_TOLERANCE * mean, 2.0 * sd / math.sqrt(x.size))
    sd_ok = abs(fit_sd - sd) <= sd * max(SD_TOLERANCE, 2.0 * math.sqrt((kurtosis - 1.0) / (4 * x.size)))
    return _Moments(fit_mean, fit_sd, mean, sd, not mean_ok, not sd_ok)


def _off(fit_value: float, value: float) -> float:
    """How far ``fit_value`` is off ``value``, as a fraction of it (inf where undefined)."""
    with np.errstate(all="ignore"):
        error = abs(fit_value / value - 1.0) if value else math.inf
    return error if math.isfinite(error) else math.inf


def caution(fit: Fit, values: ArrayLike) -> str:
    """Why ``fit`` does not stand for ``values``, naming its mean and sd and theirs; "" when
    it does.  It does not when its mean or sd is more than :data:`CAUTION_OFF` off theirs,
    or off by more than :data:`MEAN_TOLERANCE` or :data:`SD_TOLERANCE` of it and by more than
    twice their own sampling error of it (sd/√n for the mean, sd·√((kurtosis − 1)/4n) for the
    sd), or when its KS p-value is below :data:`P_FLOOR`.  A difference beyond 10 % but within
    that sampling error is said to be (the sample's own mean or sd may be what is off); data
    with few distinct values are said to be (a log's rounding alone makes the KS test reject
    every continuous fit of a large sample)."""
    x = np.asarray(values, dtype=float).ravel()
    m = _moments(fit, x)
    rejected = fit.p_value < P_FLOOR
    far = _off(m.fit_mean, m.mean) > CAUTION_OFF or _off(m.fit_sd, m.sd) > CAUTION_OFF
    if not (m.mean_off or m.sd_off or rejected or far):
        return ""
    ks = f"; the KS test rejects it (p = {fit.p_value:.2g} < {P_FLOOR:g})" if rejected else ""
    distinct = np.unique(x).size
    few = f"; the data take only {distinct} distinct values" if distinct <= x.size // 2 else ""
    moments = (f"mean {m.fit_mean:.4g} s and sd {m.fit_sd:.4g} s, the data's {m.mean:.4g} s and "
               f"{m.sd:.4g} s")
    if not (m.mean_off or m.sd_off or rejected):
        return (f"the fitted {fit.family}'s mean or sd is more than {CAUTION_OFF:.0%} off the data's: "
                f"{moments}; that is within the sampling error of {x.size} values, so the sample's own "
                f"mean or sd may be what is off{few}")
    return f"the fitted {fit.family} does not stand for these data: {moments}{ks}{few}"


def choose(fits: Sequence[Fit], values: ArrayLike,
           refused: Callable[[Fit], str] = unusable) -> tuple[Fit, str]:
    """The fit to write, and why it is not the ranking's first (or ""): the best a scenario
    accepts (``refused(fit)`` is "": by default :func:`unusable`), unless it misses the data's
    mean or sd (:data:`MEAN_TOLERANCE`, :data:`SD_TOLERANCE`); then, of the fits a scenario
    accepts, the one nearest the data's mean, and among those their sd.  ValueError, naming
    each fit and why, if a scenario accepts none.

    The mean sets the offered load, and the spread the queueing, so a fit that moves them
    misleads every what-if built on it.  On data no family describes the MLE can move them
    far: a free threshold slides next to the minimum when many gaps share it (a line that
    runs at one pace, with bursts of long gaps), and the likelihood then rewards a spike
    there far more than it is hurt by a tail the sample cannot pin down.  On gaps of 12 s
    with every fifth 60 s (mean 21.6 s, sd 19.3 s) the lognormal wins by AIC with mean
    38.8 s, the Weibull keeps the mean but has sd 106 s, and the gamma keeps the mean (its
    scale's likelihood equation makes the fitted mean the sample's whatever the threshold;
    so does the exponential's) with sd 26.1 s: the gamma is written, with a caution.  On
    samples of the families themselves (264 samples of 20 to 2,000 from six of them, a
    heavy-tailed lognormal among them) the winner's mean and sd stayed within their sampling
    error of the sample's, so the choice was the ranking's every time.
    """
    x = np.asarray(values, dtype=float).ravel()
    why_not = {id(f): refused(f) for f in fits}
    usable = [f for f in fits if not why_not[id(f)]]
    if not usable:
        raise ValueError("no fitted family gives times a scenario accepts (non-negative, with a finite "
                         "positive mean): " +
                         "; ".join(f"{f.family}: {why_not[id(f)]}" for f in fits))
    moments = [_moments(f, x) for f in usable]
    first = moments[0]
    best = 0 if not (first.mean_off or first.sd_off) else \
        min(range(len(usable)), key=lambda i: (moments[i].mean_off, moments[i].sd_error, i))
    chosen, m = usable[best], moments[best]
    if chosen is fits[0]:
        return chosen, ""
    if best == 0:
        ahead = next(i for i, f in enumerate(fits) if f is chosen)
        passed = "; ".join(f"{f.family} {why_not[id(f)]}" for f in fits[:ahead])
        return chosen, f"Chosen: {chosen.family}, the best fit a scenario accepts ({passed})."
    miss = f"has mean {first.fit_mean:.4g} s" if first.mean_off else f"has sd {first.fit_sd:.4g} s"
    return chosen, (f"Chosen: {chosen.family} (mean {m.fit_mean:.4g} s, sd {m.fit_sd:.4g} s), of the fits "
                    f"a scenario accepts the nearest the data's mean ({m.mean:.4g} s) and "
                    f"sd ({m.sd:.4g} s): the best, {usable[0].family}, {miss}.")


def first_accepted(fits: Sequence[Fit], refused: Callable[[Fit], str] = unusable) -> tuple[Fit, str]:
    """The best of ``fits`` a scenario accepts, and why it is not the ranking's first (or "");
    for censored times, whose own mean and sd are unknown, so :func:`choose` cannot compare
    them.  ValueError, naming each fit and why, if a scenario accepts none."""
    why_not = [refused(f) for f in fits]
    ahead = next((i for i, why in enumerate(why_not) if not why), None)
    if ahead is None:
        raise ValueError("no fitted family gives times a scenario accepts (non-negative, with a finite "
                         "positive mean): " +
                         "; ".join(f"{f.family}: {why}" for f, why in zip(fits, why_not)))
    if ahead == 0:
        return fits[0], ""
    passed = "; ".join(f"{f.family} {why}" for f, why in zip(fits[:ahead], why_not))
    return fits[ahead], f"Chosen: {fits[ahead].family}, the best fit a scenario accepts ({passed})."
