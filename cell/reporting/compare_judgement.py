"""``cell compare``'s verdict: per headline measure (and OEE), which of A and B is better and
by how much, read from the comparison's summary and differences tables (and its replications,
for the measures free of the arrival rate, :mod:`cell.reporting.compare_rates`), then the
overall verdict weighed by practical size (:mod:`cell.reporting.compare_verdict`).  Counts and
extremes over different windows (:mod:`cell.experiments.sweep.windows`) are left uncompared."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from cell.reporting.compare_verdict import PRACTICAL_PER_1000

if TYPE_CHECKING:
    import pandas as pd

    from cell.experiments.sweep import Sweep
    from cell.experiments.sweep.spec import Point
    from cell.reporting.compare_verdict import Judged, Verdict
    from cell.reporting.formatting import Headline
    from cell.scenario.run_length import RunLength


def verdict(summary: pd.DataFrame, differences: pd.DataFrame, sweep: Sweep,
            replications: pd.DataFrame | None = None,
            practical: float = PRACTICAL_PER_1000) -> str:
    """A few lines: per headline measure (and OEE), which is better, and A's difference from B
    (A - B) as a sentence with A its subject (``b better: a delivers 3.1 ± 0.4 parts fewer than
    b ...``), then the overall verdict (:func:`judgement`).  Counts and extremes are not
    compared if A and B take them over different windows (run length, warm-up)."""
    from cell.reporting.compare_verdict import overall_line

    lines, judged = judgement(summary, differences, sweep, replications, practical)
    return "\n".join([*lines, overall_line(judged)])


def judgement(summary: pd.DataFrame, differences: pd.DataFrame, sweep: Sweep,
              replications: pd.DataFrame | None = None,
              practical: float = PRACTICAL_PER_1000) -> tuple[list[str], Verdict]:
    """The verdict's lines but its last, and the overall verdict they lead to, weighed by
    practical size (:mod:`cell.reporting.compare_verdict`, ``practical`` parts per 1,000)."""
    from cell.experiments.sweep.spec import comparison_sides
    from cell.experiments.sweep.windows import setting, windows_apart
    from cell.reporting.compare_rates import (
        RATE_FREE,
        SHOWN_ONLY,
        rate_error_s,
        rate_free,
        rates_differ,
        still_sides,
    )
    from cell.reporting.compare_verdict import MONEY, OEE, OEE_LOSSES, SCALES, Judged, decide, losses_line
    from cell.reporting.formatting import HEADLINES
    from cell.scenario.run_length import RunLength

    (la, a), (lb, b) = comparison_sides(sweep)
    differ = windows_apart(a.scenario, b.scenario)
    errors = (rate_error_s(a.scenario.arrivals, a.scenario.base_dir),
              rate_error_s(b.scenario.arrivals, b.scenario.base_dir))
    demand = rates_differ(summary, la, lb, errors, sweep.confidence)
    length_a, length_b = RunLength.of(a.scenario.run), RunLength.of(b.scenario.run)
    length = length_a if length_a == length_b else None
    lines = [_verdict_header(sweep, la, a, lb, b, length_a, length_b)]
    if demand:
        lines.append(f"  {demand}")
    lines += [f"  {w}" for w in still_sides(summary, la, lb)]
    apart = ", ".join(f"{setting(k)} {va} against {vb}" for k, va, vb in differ)
    judged: list[Judged] = []
    measures = (*HEADLINES, OEE)
    width = max(len(t) for t in [*(h.title for h in (*measures, *MONEY)),
                                  *(r[0] for r in RATE_FREE)])
    scales = {m: _both(summary, m, la, lb) for m in SCALES}
    if not scales["parts_arrived"] > 0 and length is not None and length.unit == "part":
        scales["parts_arrived"] = float(length.number)  # a summary without the column
    for h in measures:
        line = _headline_verdict(h, summary, differences, la, lb, length, width,
                                 apart if differ else None, bool(demand), judged, scales)
        if line is not None:
            lines.append(line)
    losses = losses_line(_pairs(summary, OEE_LOSSES, la, lb), la, lb, width)
    if losses is not None:
        lines.append(losses)
    for h in MONEY:  # said where both sides have costs: or energy:, not weighed (compare_verdict)
        line = _headline_verdict(h, summary, differences, la, lb, length, width,
                                 apart if differ else None, bool(demand), [], scales)
        if line is not None:
            lines.append(line)
    if replications is not None:
        for title, side, size, line in rate_free(replications, sweep, la, lb, width):
            lines.append(line)
            if demand and title not in SHOWN_ONLY:
                judged.append(Judged(title, side, size))
    return lines, decide(judged, la, lb, practical, bool(demand))


def _pairs(summary: pd.DataFrame, measures: tuple[str, ...], la: str, lb: str
           ) -> dict[str, tuple[float, float]]:
    """Each measure's (A's mean, B's mean), for those both sides have."""
    out = {}
    for m in measures:
        rows = summary[summary["measure"] == m].set_index("scenario")["mean"]
        if {la, lb} <= set(rows.index):
            out[m] = (float(rows[la]), float(rows[lb]))
    return out


def _both(summary: pd.DataFrame, measure: str, la: str, lb: str) -> float:
    """A measure's mean over A's and B's means (NaN if either lacks it)."""
    rows = summary[summary["measure"] == measure].set_index("scenario")["mean"]
    return float((rows[la] + rows[lb]) / 2) if {la, lb} <= set(rows.index) else math.nan


def _verdict_header(sweep: Sweep, la: str, a: Point, lb: str, b: Point,
                    length_a: RunLength, length_b: RunLength) -> str:
    """The verdict's first line: the two sides, the replications, run lengths and seed."""
    level = f"{sweep.confidence * 100:g} %"
    of = (f" of {length_a}" if length_a == length_b else
          f" of {length_a.number} and {length_b}" if length_a.unit == length_b.unit else
          f" of {length_a} and {length_b}")
    return (f"{la} ({a.policy}) against {lb} ({b.policy}): {sweep.replications} replications"
            f"{of}, seed {sweep.seed}, common random numbers; A - B with its paired "
            f"{level} confidence interval")


def _headline_verdict(h: Headline, summary: pd.DataFrame, differences: pd.DataFrame, la: str,
                      lb: str, length: RunLength | None, width: int, apart: str | None,
                      demand: bool, weighed: list[Judged], scales: dict[str, float]) -> str | None:
    """One headline measure's verdict line (None if it was not measured); its side (1: A
    better, -1: B better, 0: neither) and size (parts per 1,000; ``scales``: the parts
    arrived and delivered, the means of both sides) are appended to ``weighed`` unless the
    arrival rates differ and the measure grows with the demand.  ``apart``: how the runs'
    windows differ, None if they do not."""
    from cell.experiments.sweep.windows import window_kind
    from cell.reporting.compare_verdict import Judged, per_1000
    from cell.reporting.formatting import better, number, too_few

    d = differences[differences["measure"] == h.column]
    windowed = window_kind(h.column)
    if windowed and apart is not None and h.column in set(summary["measure"]):
        return (f"  {h.title:<{width}}  not compared: {windowed}, over different "
                f"windows ({apart}); compare the rates")
    if d.empty:
        return None
    row = d.iloc[0]
    means = summary[summary["measure"] == h.column].set_index("scenario")["mean"]
    if int(row["n"]) < 2:
        return (f"  {h.title:<{width}}  not compared: "
                f"{too_few(int(row['n']), sides='both A and B')}")
    what, judged = _difference_said(h, row, la, lb, length)
    side = better(h, float(means[la]), float(means[lb])) if judged else 0
    who = {1: f"{la} better", -1: f"{lb} better", 0: "neither"}[side]
    if h.better == "one" and side:
        who += " (nearer 1 is better)"
    if demand and h.column in DEMAND_BOUND:
        who = "not judged (arrival rates differ)"
    else:
        weighed.append(Judged(h.title, side, per_1000(h.column, float(row["mean"]),
                                                      float(means[la]), float(means[lb]), scales)))
    shown = f"{number(float(means[la]))} against {number(float(means[lb]))}"
    return f"  {h.title:<{width}}  {who}: {what}; means {shown}"


def _difference_said(h: Headline, row: pd.Series, la: str, lb: str,
                     length: RunLength | None) -> tuple[str, bool]:
    """A - B for one measure as a sentence with A its subject, and whether it is judged (the
    paired interval excludes 0, or A and B differ by the same in every replication)."""
    from cell.reporting.formatting import half_width, number, plus_minus

    mean, sd, lo, hi = (float(row[k]) for k in ("mean", "sd", "ci_low", "ci_high"))
    if sd == 0.0:
        what = (f"{la} and {lb} equal in every replication" if mean == 0 else
                f"{h.says(la, number(abs(mean)), mean, lb, length)} in every replication")
        return what, bool(mean != 0)
    judged = not (lo <= 0.0 <= hi)
    what = (f"{h.says(la, plus_minus(abs(mean), half_width(row)), mean, lb, length)} "
            + ("(interval excludes 0)" if judged else
               "(interval includes 0: no difference shown)"))
    return what, judged


#: Measures that grow with the demand: with different arrival rates they say more parts
#: came, not which cell is better, and are left unjudged (the rate-free ones judge).
DEMAND_BOUND = frozenset({"parts_per_hr_wallclock", "parts_delivered", "parts_missed",
                          "spacing_outside_tol", "actual_cycle_wallclock_s", "oee"})
