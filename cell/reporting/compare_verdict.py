"""``cell compare``'s overall verdict, weighed by practical size (docs/usage.md, "The overall
verdict").

A difference the paired interval shows (it excludes 0) may still be too small to matter: a
quarter of a spacing error per 1,000 parts against 177 more parts delivered a run is not a
mixed result.  So each measure's difference is put in one unit, parts per 1,000 (per mille,
‰), and judged against a stated practical threshold (:data:`PRACTICAL_PER_1000`, ``cell
compare --practical``):

- a count per run (parts delivered, parts lost) as a share of the parts that arrived; spacings
  outside the tolerance as a share of the parts delivered;
- a rate (parts per hour) as the parts it brings per 1,000 that arrive (over the arrivals per
  hour), and the actual cycle likewise (through the parts per hour it gives, 3600 / cycle), so
  the four faces of one throughput have about the same size;
- IP by its distance from 1 (eq. 5.1: deliveries over arrivals), and a share (OEE, the service
  level) as it is: 0.001 is 1 ‰; a percentage (parts lost per 100 arrivals) tenfold.

A difference shown but below the threshold is *trivial*: it is said, and it does not sway the
verdict.  The measures are not independent (parts delivered, parts lost, parts per hour and
the cycle are one throughput seen four ways), so their sizes are not added: the largest
practical difference decides which side is better, and practical differences the other way
are named with it as its trade-offs.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from cell.reporting.formatting import Headline

#: The default practical threshold, parts per 1,000: a difference smaller than one part in a
#: thousand does not decide a verdict.
PRACTICAL_PER_1000 = 1.0

#: OEE in the verdict (ISO 22400-2: availability × performance × quality; :mod:`cell.sim.oee`):
#: a share of the planned busy time, higher is better.
OEE = Headline("oee", "OEE (ISO 22400-2, A × P × Q)",
               "{a} reaches an OEE {x} {dir} than {b}", ("higher", "lower"), "higher")
#: Money and energy, where the scenarios give ``costs:`` and ``energy:`` (summary.csv's optional
#: columns): each paired difference said with its interval, lower is better; not weighed in the
#: overall line, whose unit is parts per 1,000 (a cost is the user's own rule of value).
MONEY = (
    Headline("cost_per_good_part", "Cost per good part", "{a} costs {x} {dir} a good part than {b}",
             ("more", "less"), "lower"),
    Headline("cost_per_h", "Cost per hour", "{a} costs {x} {dir} an hour than {b}",
             ("more", "less"), "lower"),
    Headline("energy_per_good_part_wh", "Energy per good part (Wh)",
             "{a} uses {x} Wh {dir} a good part than {b}", ("more", "less"), "lower"),
)
#: Where each side's planned busy time went, shown under OEE (summary.csv's names), not judged.
OEE_LOSSES = ("loss_downtime", "loss_starved", "loss_blocked", "loss_speed", "loss_quality")


def losses_line(means: Mapping[str, tuple[float, float]], a: str, b: str, width: int
                ) -> str | None:
    """The OEE losses' means, A's against B's, as shares of the planned busy time (those
    measured); None if none was."""
    shown = [f"{name} {pa:.1%} against {pb:.1%}" for name in OEE_LOSSES
             if name in means for pa, pb in [means[name]]]
    if not shown:
        return None
    return (f"  {'OEE losses':<{width}}  shares of the planned busy time, {a} against {b}: "
            + "; ".join(shown))

#: How a measure's difference becomes parts per 1,000: ``("of", measure)``, a count over
#: another measure's mean (per run); ``("per_hour", None)``, parts per hour over the arrivals
#: per hour; ``("cycle", None)``, the same through 3600 / cycle; ``("one", None)``, the change
#: in its distance from 1; ``("share", None)``, a fraction as it is.
PER_1000: dict[str, tuple[str, str | None]] = {
    "parts_delivered": ("of", "parts_arrived"),
    "parts_missed": ("of", "parts_arrived"),
    "spacing_outside_tol": ("of", "parts_delivered"),
    "parts_per_hr_wallclock": ("per_hour", None),
    "actual_cycle_wallclock_s": ("cycle", None),
    "ip_wallclock": ("one", None),
    "oee": ("share", None),
}
#: The means :func:`per_1000` reads beside a measure's own (over both sides).
SCALES = ("parts_arrived", "parts_delivered", "mean_interarrival_s")


def per_1000(measure: str, difference: float, mean_a: float, mean_b: float,
             means: Mapping[str, float]) -> float:
    """``measure``'s difference A - B in parts per 1,000 (its size, not signed); ``means``:
    other measures' means over both sides (:data:`SCALES`).  NaN if it has no such unit or its
    denominator is unknown."""
    kind, of = PER_1000.get(measure, ("", None))
    gap = means.get("mean_interarrival_s", math.nan)  # s between arrivals: 3600 / gap an hour
    if kind == "of":
        den = means.get(of or "", math.nan)
        return 1000.0 * abs(difference) / den if den > 0 else math.nan
    if kind == "per_hour":
        return 1000.0 * abs(difference) * gap / 3600.0 if gap > 0 else math.nan
    if kind == "cycle":
        if not (gap > 0 and mean_a > 0 and mean_b > 0):
            return math.nan
        return 1000.0 * gap * abs(1.0 / mean_a - 1.0 / mean_b)
    if kind == "one":
        return 1000.0 * abs(abs(mean_a - 1.0) - abs(mean_b - 1.0))
    if kind == "share":
        return 1000.0 * abs(difference)
    return math.nan


@dataclass(frozen=True)
class Judged:
    """One measure as the verdict weighs it."""

    title: str
    side: int
    """+1: A better, -1: B better, 0: no difference shown (the interval holds 0)."""
    size_per_1000: float
    """The difference's size, parts per 1,000 (NaN: no common unit; then it counts as
    practical, as every shown difference did before sizes were weighed)."""

    def practical(self, threshold: float) -> bool:
        return bool(self.side) and not self.size_per_1000 < threshold


@dataclass(frozen=True)
class Verdict:
    """The overall verdict, which the prose is made from."""

    a: str
    b: str
    better: int
    """+1: A better, -1: B better, 0: no practical difference shown."""
    deciding: str | None
    """The measure with the largest practical difference (it names the better side)."""
    against: tuple[str, ...]
    """Practical differences the other way (the trade-offs)."""
    trivial: tuple[str, ...]
    """Differences shown (the interval excludes 0) but below the threshold."""
    threshold_per_1000: float
    judged: tuple[Judged, ...]
    rate_free: bool
    """Judged on the rate-free measures (the arrival rates differ)."""

    @property
    def winner(self) -> str | None:
        return {1: self.a, -1: self.b}.get(self.better)

    def size(self, title: str) -> float:
        return next(j.size_per_1000 for j in self.judged if j.title == title)


def decide(judged: Sequence[Judged], a: str, b: str, threshold: float,
           rate_free: bool = False) -> Verdict:
    """The side of the largest practical difference, with the practical ones the other way and
    the trivial ones beside it."""
    practical = [j for j in judged if j.practical(threshold)]
    trivial = tuple(j.title for j in judged if j.side and not j.practical(threshold))
    if not practical:
        return Verdict(a, b, 0, None, (), trivial, threshold, tuple(judged), rate_free)
    top = max(practical, key=lambda j: j.size_per_1000 if j.size_per_1000 == j.size_per_1000
              else -math.inf)
    against = tuple(j.title for j in practical if j.side == -top.side)
    return Verdict(a, b, top.side, top.title, against, trivial, threshold, tuple(judged),
                   rate_free)


def _size(v: Verdict, title: str) -> str:
    s = v.size(title)
    return f"{s:.3g} per 1,000" if s == s else "no common unit"


def overall_line(v: Verdict) -> str:
    """The verdict's last line, from :class:`Verdict`."""
    basis = ("the rate-free measures (the arrival rates differ)" if v.rate_free else
             "the headline measures")
    n = len(v.judged)
    na = sum(1 for j in v.judged if j.side > 0)
    nb = sum(1 for j in v.judged if j.side < 0)
    counts = f"{v.a} better on {na}, {v.b} on {nb}, neither on {n - na - nb} of {n}"
    if v.deciding is None:
        head = "no practical difference shown"
    else:
        head = f"{v.winner} better, decided by {v.deciding} ({_size(v, v.deciding)})"
        if v.against:
            loser = v.b if v.better > 0 else v.a
            head += ("; against it, " + ", ".join(f"{t} ({_size(v, t)})" for t in v.against)
                     + f" where {loser} is better")
    tail = ""
    if v.trivial:
        tail = (f"; below the practical threshold of {v.threshold_per_1000:g} per 1,000: "
                + ", ".join(f"{t} ({_size(v, t)})" for t in v.trivial))
    return f"Overall, on {basis}: {head} ({counts}){tail}"
