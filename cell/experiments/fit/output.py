"""What ``cell fit`` prints and writes: the table of fits beside the data's mean and sd, and
the scenario block of the chosen fit (``arrivals:``, or ``time_to_failure:`` /
``time_to_repair:`` for the ``failures:`` section), each parameter spelt so YAML reads it back."""

from __future__ import annotations

import math
import textwrap
from collections.abc import Callable, Sequence
from typing import NamedTuple

from cell.experiments.fit.mle import Fit


class DataMoments(NamedTuple):
    """The data's row of the table: how many values, and their mean and sd (NaN: not known,
    as under censoring); ``note`` in the parameters' column."""

    n: int
    mean: float
    sd: float
    note: str = ""


def _digits(name: str, params: dict[str, float], base: int) -> int:
    """Significant digits for a parameter: ``base``, more for a ``loc`` far larger than
    the ``scale``, so rounding it moves the distribution by < 10^-base scales."""
    loc, scale = abs(params.get("loc", 0.0)), abs(params.get("scale", 0.0))
    if name != "loc" or loc == 0.0 or scale == 0.0 or loc <= scale:
        return base
    return min(base + math.ceil(math.log10(loc / scale)), 17)


def _yaml_float(v: float, digits: int = 7) -> str:
    """``v`` to ``digits`` significant digits, spelt so YAML 1.1 (PyYAML) reads a float."""
    if not math.isfinite(v):
        raise ValueError(f"parameter {v!r} is not finite")
    s = f"{v:.{digits}g}"
    mant, e, exp = s.partition("e")
    if "." not in mant:
        mant += ".0"
    return mant + e + exp


def _comments(text: str) -> str:
    """``text`` as YAML comment lines, wrapped at 100 characters."""
    return "".join(f"# {line}\n" for line in textwrap.wrap(" ".join(text.split()), 98))


def ks_line(fit: Fit) -> str:
    """The written block's line on how ``fit`` was made and how well it fits."""
    return (f"maximum likelihood; Kolmogorov-Smirnov D = {fit.statistic:.4g} "
            f"(p = {fit.p_value:.3g}, optimistic with fitted parameters), AIC = {fit.aic:.1f}")


def block_yaml(fit: Fit, key: str, source: str, *, caution: str = "", notes: Sequence[str] = (),
               method: str = "") -> str:
    """The scenario block ``key: {distribution, params}`` for ``fit`` (a time to failure or
    repair by its mean in hours and its shape where :func:`by_mean_lines` can), with comments
    naming ``source``, how it was fitted (``method``, by default :func:`ks_line`), each of
    ``notes`` and ``caution`` (as a ``CAUTION:`` line) when there is one, each wrapped."""
    source = " ".join(source.split())  # one comment line, whatever the name holds
    params = ", ".join(f"{k}: {_yaml_float(v, _digits(k, fit.params, 7))}" for k, v in fit.params.items())
    said = "".join(_comments(note) for note in notes if note)
    warned = _comments(f"CAUTION: {caution}") if caution else ""
    given = by_mean_lines(fit) if key in FAILURE_BLOCKS else None
    return (f"# fitted by `cell fit` from {source}\n"
            f"# {method or ks_line(fit)}\n"
            f"{said}{warned}{key}:\n"
            f"  distribution: {fit.family}\n"
            + (given or f"  params: {{{params}}}\n"))


#: The blocks of the ``failures:`` section, written by their mean where the family allows.
FAILURE_BLOCKS = ("time_to_failure", "time_to_repair")


def by_mean_lines(fit: Fit) -> str | None:
    """``mean_h`` and ``shape`` lines for a fit the ``failures:`` section can take by its mean
    (weibull_min, gamma, lognorm with no location; expon by its mean alone), each to seven
    digits; None for any other."""
    from cell.scenario.spread import SHAPE_PARAM

    if fit.family not in SHAPE_PARAM or fit.params.get("loc", 0.0) != 0.0:
        return None
    mean_s = float(fit.frozen().mean())
    shape = SHAPE_PARAM[fit.family]
    if not (math.isfinite(mean_s) and mean_s > 0) or (shape is not None and shape not in fit.params):
        return None
    lines = f"  mean_h: {_yaml_float(mean_s / 3600.0)}\n"
    return lines + (f"  shape: {_yaml_float(fit.params[shape])}\n" if shape is not None else "")


def arrivals_yaml(fit: Fit, source: str, caution: str = "") -> str:
    """The scenario's ``arrivals:`` block for ``fit`` (:func:`block_yaml`)."""
    return block_yaml(fit, "arrivals", source, caution=caution)


def _seconds(v: float) -> str:
    return f"{v:.4g}" if math.isfinite(v) else ("-" if math.isnan(v) else "inf")


def format_table(fits: Sequence[Fit], data: DataMoments | None = None,
                 note: Callable[[Fit], str] | None = None, *, censored: bool = False) -> str:
    """The candidates as a text table, in the order given (best first), each fit's mean and sd
    (s) beside the data's (the first row, when ``data`` is given), and ``note(fit)`` (by
    default: "allows negative times" where it does).  ``censored``: D is the distance to the
    Kaplan-Meier estimate, and there is no p-value."""
    def noted(f: Fit) -> str:
        return note(f) if note is not None else "" if f.nonnegative else "allows negative times"

    rows = [("rank", "family", "parameters", "mean s", "sd s", "KM D" if censored else "KS D",
             "KS p", "log-lik", "AIC", "")]
    if data is not None:
        rows.append(("", "data", data.note or f"n = {data.n}", _seconds(data.mean), _seconds(data.sd),
                     "", "", "", "", ""))
    for i, f in enumerate(fits, start=1):
        params = ", ".join(f"{k}={v:.{_digits(k, f.params, 4)}g}" for k, v in f.params.items())
        mean, sd, _ = f.fitted_moments()
        p = "-" if math.isnan(f.p_value) else f"{f.p_value:.3g}"
        rows.append((str(i), f.family, params, _seconds(mean), _seconds(sd), f"{f.statistic:.4f}", p,
                     f"{f.loglik:.1f}", f"{f.aic:.1f}", noted(f)))
    widths = [max(len(r[j]) for r in rows) for j in range(len(rows[0]))]
    right = {0, 3, 4, 5, 6, 7, 8}
    lines = ["  ".join(c.rjust(w) if j in right else c.ljust(w) for j, (c, w) in enumerate(zip(r, widths)))
             .rstrip() for r in rows]
    lines.append("D: the largest distance between each fitted cdf and the Kaplan-Meier estimate (no "
                 "p-value under censoring)." if censored else
                 "KS p-values are optimistic: the parameters were fitted to these data.")
    return "\n".join(lines)
