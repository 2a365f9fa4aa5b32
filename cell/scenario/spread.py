"""A distribution given by its mean and its spread: the scipy.stats parameters of a family
with a stated mean and a stated shape or coefficient of variation (cv = sd / mean).

One rule for every time a scenario gives this way: the arrivals' ``mean_s`` and ``cv``, and
a failure's or repair's ``mean_s`` or ``mean_h`` with ``shape`` or ``cv``.
"""

from __future__ import annotations

import math

#: Families whose shape and scale follow from a mean and a shape or coefficient of variation.
BY_MEAN_AND_CV = ("gamma", "weibull_min", "lognorm", "expon")
#: Each family's ``shape``, by scipy's name for it (the exponential has none).
SHAPE_PARAM = {"gamma": "a", "weibull_min": "c", "lognorm": "s", "expon": None}


def by_mean_and_cv(family: str, mean: float, cv: float) -> dict[str, float]:
    """Shape and scale of ``family`` with this mean and coefficient of variation
    (:func:`by_mean`)."""
    return by_mean(family, mean, cv=cv)


def by_mean(family: str, mean: float, *, shape: float | None = None,
            cv: float | None = None) -> dict[str, float]:
    """The scipy parameters of ``family`` with this mean and either its ``shape`` (scipy's
    shape parameter: gamma's a, weibull_min's c, lognorm's s) or its ``cv``; no location,
    except the shifted exponential's.

    gamma: a = shape or 1/cv², scale = mean/a (mean·cv² from a cv);
    lognorm: s = shape or √ln(1 + cv²), scale = mean/exp(s²/2) (mean/√(1 + cv²) from a cv);
    weibull_min: c = shape, or c solves Γ(1 + 2/c)/Γ(1 + 1/c)² = 1 + cv²; scale = mean/Γ(1 + 1/c);
    expon: scale = mean (cv 1); with a cv, shifted: loc = mean(1 − cv), scale = mean·cv (cv ≤ 1).
    A ValueError says why a combination has no such distribution.
    """
    if shape is not None and cv is not None:
        raise ValueError("give a shape or a cv, not both")
    if family not in BY_MEAN_AND_CV:
        raise ValueError(f"a mean and a spread set the shape of {', '.join(BY_MEAN_AND_CV)} only")
    if family == "expon" and shape is not None:
        raise ValueError("an exponential has no shape: its mean sets it")
    if cv is not None:
        return _from_cv(family, mean, cv)
    if shape is not None:
        return _from_shape(family, mean, shape)
    if family == "expon":
        return {"scale": mean}
    raise ValueError(f"{family} needs a shape or a cv beside its mean")


def _from_cv(family: str, mean: float, cv: float) -> dict[str, float]:
    if family == "gamma":
        return {"a": 1.0 / cv**2, "scale": mean * cv**2}
    if family == "lognorm":
        return {"s": math.sqrt(math.log1p(cv**2)), "scale": mean / math.sqrt(1.0 + cv**2)}
    if family == "expon":
        if cv > 1:
            raise ValueError("a shifted exponential has a coefficient of variation of at most 1")
        return {"loc": mean * (1.0 - cv), "scale": mean * cv}
    return _from_shape(family, mean, weibull_shape(cv))


def _from_shape(family: str, mean: float, shape: float) -> dict[str, float]:
    if family == "gamma":
        return {"a": shape, "scale": mean / shape}
    if family == "lognorm":
        return {"s": shape, "scale": mean * math.exp(-0.5 * shape * shape)}
    from scipy.special import gammaln

    return {"c": shape, "scale": mean / math.exp(gammaln(1 + 1 / shape))}


def weibull_shape(cv: float) -> float:
    """The Weibull shape c whose coefficient of variation is ``cv``:
    Γ(1 + 2/c)/Γ(1 + 1/c)² = 1 + cv², solved between c = 0.05 and 10⁴."""
    from scipy.optimize import brentq
    from scipy.special import gammaln

    def excess(log_c: float) -> float:
        c = math.exp(log_c)
        return math.exp(gammaln(1 + 2 / c) - 2 * gammaln(1 + 1 / c)) - 1.0 - cv**2

    return math.exp(brentq(excess, math.log(0.05), math.log(1e4), xtol=1e-14))
