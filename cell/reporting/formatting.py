"""The headline measures of an experiment's report, how to say a difference in words,
and the number and markdown-table formatting the reports share.

A report summarises every numeric column of the runs' summaries (new columns of
:class:`cell.sim.records.RunSummary` flow through untouched); these few get a table,
a figure and sentences of their own.  Which direction is better is part of the
measure: more parts delivered, fewer lost, a shorter cycle, an IP nearer 1
(eq. 5.1: deliveries keeping pace with arrivals).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import pandas as pd

    from cell.scenario.run_length import RunLength


@dataclass(frozen=True)
class Headline:
    """A measure the report leads with."""

    column: str
    title: str
    """As a heading: ``Parts delivered``."""
    sentence: str
    """``{a} ... {x} ... {dir} than {b}``: how a paired difference reads."""
    words: tuple[str, str]
    """The words for a positive and a negative difference: ``more``/``fewer``."""
    better: str
    """``higher``, ``lower`` or ``one`` (nearer 1 is better)."""
    per_run: bool = False
    """A count per run: the sentence says ``per N-part run`` (or ``per N-hour run``)."""

    def says(self, a: str, x: str, mean: float, b: str, length: RunLength | None) -> str:
        """``a``'s paired difference ``mean`` from ``b`` in words, ``x`` its size as shown:
        ``a delivers 3.1 ± 0.4 parts more than b per 500-part run``."""
        direction = self.words[0] if mean >= 0 else self.words[1]
        per = f" per {length.run}" if self.per_run and length else ""
        return self.sentence.format(a=a, x=x, dir=direction, b=b) + per


HEADLINES: tuple[Headline, ...] = (
    Headline("parts_delivered", "Parts delivered", "{a} delivers {x} parts {dir} than {b}",
             ("more", "fewer"), "higher", per_run=True),
    Headline("parts_missed", "Parts lost (wall clock)", "{a} loses {x} parts {dir} than {b}",
             ("more", "fewer"), "lower", per_run=True),
    Headline("parts_per_hr_wallclock", "Parts per hour (wall clock)",
             "{a} delivers {x} parts/hr {dir} than {b} on the wall clock",
             ("more", "fewer"), "higher"),
    Headline("actual_cycle_wallclock_s", "Actual cycle (wall clock, s)",
             "{a} runs a wall-clock actual cycle {x} s {dir} than {b}",
             ("longer", "shorter"), "lower"),
    Headline("ip_wallclock", "IP (wall clock, eq. 5.1)",
             "{a} reaches a wall-clock IP {x} {dir} than {b}", ("higher", "lower"), "one"),
    Headline("spacing_outside_tol", "Spacings outside 45 ± 0.25 in",
             "{a} leaves {x} {dir} spacings outside 45 ± 0.25 in than {b}",
             ("more", "fewer"), "lower", per_run=True),
)


def too_few(n: int | None, what: str = "it", sides: str = "both", why: bool = True) -> str:
    """Why a paired difference is not compared: fewer than two replications give ``what``
    for ``sides`` (``n`` of them, 0 or 1; None: either); ``why`` adds the usual cause."""
    have = ("no replication gives" if n == 0 else "only one replication gives" if n == 1
            else "fewer than two replications give")
    cause = " (e.g. runs too short to deliver two parts)" if why else ""
    return f"{have} {what} for {sides}{cause}"


def decimals(half: float) -> int:
    """Decimals that show a confidence half-width to two significant figures (0 to 6)."""
    if not math.isfinite(half) or half <= 0:
        return 4
    return min(6, max(0, 1 - math.floor(math.log10(half))))


#: Beyond this magnitude figures are printed in exponent form.
HUGE = 1e7


def number(value: float, places: int | None = None) -> str:
    """A figure for the text: ``places`` decimals, or six significant figures."""
    if not math.isfinite(value):
        return "—"
    if places is None or abs(value) >= HUGE:
        return f"{value:.6g}" if places is None else f"{value:.3g}"
    return f"{value:.{places}f}"


def half_width(row: Mapping[Any, Any] | pd.Series) -> float:
    """Half the width of a summary or difference row's confidence interval."""
    return (float(row["ci_high"]) - float(row["ci_low"])) / 2


def no_interval(half: float) -> str:
    """Why a confidence half-width is not a number: NaN, fewer than two replications (or runs
    that give the measure); infinite, the replications' spread overflowed a float."""
    return ("no interval: fewer than two replications" if half != half else
            "no interval: the replications' spread overflows")


def estimate(mean: float, half: float, fmt: str = ".4g", half_fmt: str = ".2g") -> str:
    """``mean ± half`` in ``fmt`` and ``half_fmt``; never ``nan`` or ``inf``: a mean that is not
    a number is ``n/a``, a half-width that is not one is said in words (:func:`no_interval`)."""
    if not math.isfinite(mean):
        return "n/a (no run gives it)" if mean != mean else "n/a (overflows)"
    if not math.isfinite(half):
        return f"{mean:{fmt}} ({no_interval(half)})"
    return f"{mean:{fmt}} ± {half:{half_fmt}}"


def plus_minus(mean: float, half: float, signed: bool = False) -> str:
    """``mean ± half`` to the half-width's two significant figures (exponent form if huge);
    never ``nan`` or ``inf`` (:func:`estimate`)."""
    sign = "+" if signed else ""
    if not (math.isfinite(mean) and math.isfinite(half)):
        return estimate(mean, half, f"{sign}.6g")
    if max(abs(mean), abs(half)) >= HUGE:
        return f"{mean:{sign}.3g} ± {half:.2g}"
    d = decimals(half)
    return f"{mean:{sign}.{d}f} ± {half:.{d}f}"


def better(h: Headline, a: float, b: float) -> int:
    """+1 if ``a`` is better than ``b`` on this measure, -1 if worse, 0 if level."""
    if not (math.isfinite(a) and math.isfinite(b)) or a == b:
        return 0
    if h.better == "one":
        da, db = abs(a - 1.0), abs(b - 1.0)
        return 0 if da == db else (1 if da < db else -1)
    return (1 if a > b else -1) * (1 if h.better == "higher" else -1)


def table_row(cells: Iterable[str]) -> str:
    """A markdown table row: ``| a | b |``; a ``|`` within a cell is escaped (``\\|``),
    so it does not split the cell."""
    return "| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |"


def table_head(head: Sequence[str]) -> list[str]:
    """A markdown table's header row and its rule."""
    return [table_row(head), "|" + "---|" * len(head)]
