"""Table 7.1's reading: sentences drawn from the numbers (thesis §7.2; docs/accounting.md).

The readings of :mod:`cell.reporting.table_7_1`, one per kind of published
figures: a policy published row by row (Table 7.1: agreement, and where the two
accountings part, docs/accounting.md) and one published as a single run (the
adaptive IP of §7.2).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from cell.reporting import published

ACCOUNTINGS = ("thesis", "wallclock")
MEASURES = published.TABLE_7_1_MEASURES
LABELS = {"actual_cycle_s": "actual cycle (s)", "parts_missed": "parts missed",
          "parts_per_hr": "parts/hr", "vavg_r4_in_s": "Vavg R IV (in/s)", "ip": "IP"}


def thesis_value(policy: str, cycle: float, accounting: str, measure: str) -> float:
    """The published figure, or NaN; published figures are all in the thesis's accounting."""
    figures = published.PUBLISHED.get(policy)
    value = figures.value(cycle, measure) if figures and accounting == "thesis" else None
    return math.nan if value is None else float(value)


def inside(thesis: float, low: float, high: float, measure: str) -> bool:
    """Whether a published figure lies in [low, high], to the thesis's printed precision
    (four decimals; parts missed are whole numbers)."""
    tol = 0.0 if measure == "parts_missed" else 0.5e-4
    return low - tol <= thesis <= high + tol


def row_of(table: pd.DataFrame, policy: str, cycle: float, accounting: str,
         measure: str) -> Mapping[str, Any]:
    sel = table[(table["policy"] == policy) & np.isclose(table["ideal_cycle_s"], cycle)
                & (table["accounting"] == accounting) & (table["measure"] == measure)]
    return {str(k): v for k, v in sel.iloc[0].to_dict().items()}


def _cycles(cycles: Sequence[float]) -> str:
    text = [f"{c:.4f}" if c != round(c, 1) else f"{c:.1f}" for c in cycles]
    return ", ".join(text[:-1]) + " and " + text[-1] if len(text) > 1 else text[0]


Means = Mapping[tuple[float, str, str], Any]


def _against_thesis(table: pd.DataFrame, policy: str, cycles: list[float]) -> list[str]:
    """How many published parts missed, actual cycles and IPs fall inside the range of 95 %
    of single runs (thesis's accounting), and how far Vavg R IV is from its column."""
    out: list[str] = []
    checked, outside = 0, []
    for c in cycles:
        for m in ("parts_missed", "actual_cycle_s", "ip"):
            r = row_of(table, policy, c, "thesis", m)
            if math.isfinite(r["thesis"]):
                checked += 1
                if not inside(r["thesis"], r["run_p2_5"], r["run_p97_5"], m):
                    outside.append(f"{LABELS[m]} at {c:.4f} s")
    if checked:
        out.append(
            f"**Against the thesis.** In the thesis's accounting the published parts missed, "
            f"actual cycle and IP fall inside the range of 95 % of single runs in "
            f"{checked - len(outside)} of {checked} cases"
            + (f" (outside: {'; '.join(outside)})." if outside else ".")
        )
    vrows = [row_of(table, policy, c, "thesis", "vavg_r4_in_s") for c in cycles]
    vv = [abs(r["mean"] - r["thesis"]) for r in vrows if math.isfinite(r["thesis"])]
    if vv:
        fixed = all(r["run_p2_5"] == r["run_p97_5"] for r in vrows)
        out.append(f"Vavg R IV differs from the published column by at most {max(vv):.5f} in/s"
                   + (" (the R IV length over the shortened R IV time: the same in every run)."
                      if fixed else "."))
    return out


def _where_parted(mean: Means, cycles: list[float], parts: int | None) -> str:
    """Parts missed and actual cycle in both accountings at the longest and shortest cycle."""
    top, bottom = cycles[0], cycles[-1]
    tm, wm = mean[top, "thesis", "parts_missed"], mean[top, "wallclock", "parts_missed"]
    ta, wa = mean[top, "thesis", "actual_cycle_s"], mean[top, "wallclock", "actual_cycle_s"]
    tb, wb = mean[bottom, "thesis", "actual_cycle_s"], mean[bottom, "wallclock", "actual_cycle_s"]
    tmb, wmb = mean[bottom, "thesis", "parts_missed"], mean[bottom, "wallclock", "parts_missed"]
    of = f" of {parts}" if parts else ""
    gap_top, gap_bottom = ta / wa - 1, tb / wb - 1
    trend = ("narrows as the cycle shortens and losses grow rare"
             if abs(gap_bottom) < abs(gap_top) else "widens as the cycle shortens")
    return (
        f"**Where the accountings part.** At {top:.4f} s the thesis's bookkeeping loses "
        f"{tm:.1f}{of} parts on average against {wm:.1f} on the wall clock, and its actual "
        f"cycle is {ta:.2f} s against {wa:.2f} s ({gap_top:+.1%}). At {bottom:.4f} s it is "
        f"{tmb:.1f} against {wmb:.1f} parts and {tb:.2f} against {wb:.2f} s "
        f"({gap_bottom:+.1%}): the gap {trend}.")


def _why_losses_differ(mean: Means, cycles: list[float]) -> list[str]:
    """Why the thesis loses more (D = T + C) or fewer parts than the wall clock, by cycle."""
    out: list[str] = []
    more = [c for c in cycles
            if mean[c, "thesis", "parts_missed"] > mean[c, "wallclock", "parts_missed"] + 0.5]
    fewer = [c for c in cycles
             if mean[c, "thesis", "parts_missed"] < mean[c, "wallclock", "parts_missed"] - 0.5]
    if more:
        out.append(
            f"Why, at {_cycles(more)} s, where the thesis loses more: it counts a part lost "
            "whenever its own inter-arrival time is shorter than the robot cycle (less a small "
            "slack), whatever the robot is doing, and books a lost part as one more robot cycle "
            "between deliveries (D = T + C). On the wall clock a robot left idle by a lost part "
            "is ready for the next one, so losses cannot come twice running, and a lost part "
            "costs only the wait for the next.")
    if fewer:
        out.append(
            f"At {_cycles(fewer)} s the thesis loses fewer than the wall clock: it judges each "
            "inter-arrival time on its own, while on the wall clock the robot's lag builds up "
            "over runs of gaps each a little shorter than the cycle, until a part is missed.")
    if not more and not fewer:
        out.append(
            "Both accountings lose the same number of parts; they part in how the time between "
            "deliveries is booked: the thesis adds a whole robot cycle per lost part (D = T + C).")
    return out


def _ip_ratio(mean: Means, cycles: list[float]) -> list[str]:
    """The thesis's IP column, T(i+1) / (2 D(i)), against the wall-clock IP."""
    top, bottom = cycles[0], cycles[-1]
    ratios = [mean[c, "wallclock", "ip"] / mean[c, "thesis", "ip"] for c in cycles
              if mean[c, "thesis", "ip"] > 0]
    if not ratios:
        return []
    return [
        f"IP: the thesis's column averages T(i+1) / (2 D(i)), a doubled denominator, so it "
        f"reads {min(ratios):.2f}–{max(ratios):.2f} times lower than the wall-clock IP "
        f"({mean[top, 'thesis', 'ip']:.4f} against {mean[top, 'wallclock', 'ip']:.4f} at "
        f"{top:.4f} s, {mean[bottom, 'thesis', 'ip']:.4f} against "
        f"{mean[bottom, 'wallclock', 'ip']:.4f} at {bottom:.4f} s)."]


def _throughput(mean: Means, policy: str, cycles: list[float], parts: int | None) -> list[str]:
    """Parts/hr at the longest cycle against the ideal cycle's, the table's and the text's cut."""
    top = cycles[0]
    tm = mean[top, "thesis", "parts_missed"]
    ideal_pph = 3600 / top
    cut_t = 1 - mean[top, "thesis", "parts_per_hr"] / ideal_pph
    cut_w = 1 - mean[top, "wallclock", "parts_per_hr"] / ideal_pph
    thesis_pph = thesis_value(policy, top, "thesis", "parts_per_hr")
    if not (math.isfinite(thesis_pph) and parts):
        return []
    return [
        f"Throughput at {top:.4f} s: the thesis's accounting gives "
        f"{mean[top, 'thesis', 'parts_per_hr']:.1f} parts/hr, {cut_t:.0%} below the "
        f"{ideal_pph:.1f}/hr of the ideal cycle (the thesis's table: "
        f"{1 - thesis_pph / ideal_pph:.0%}), while {tm / parts:.1%} of the parts are lost "
        f"(the thesis's text: {published.TEXT_THROUGHPUT_CUT:.1%}, 206 of 500): the table's parts/hr and "
        f"the text's throughput cut measure different things. On the wall clock the cut is "
        f"{cut_w:.0%}."]


def reading_by_cycle(table: pd.DataFrame, policy: str, parts: int | None,
                      replications: pd.DataFrame | None = None) -> list[str]:
    """A policy published row by row (Table 7.1): agreement, and where the accountings part."""
    cycles = list(dict.fromkeys(table.loc[table["policy"] == policy, "ideal_cycle_s"]))
    mean = {(c, a, m): row_of(table, policy, c, a, m)["mean"]
            for c in cycles for a in ACCOUNTINGS for m in MEASURES}
    out = _against_thesis(table, policy, cycles)
    out.append(_where_parted(mean, cycles, parts))
    out += _why_losses_differ(mean, cycles)
    out += _ip_ratio(mean, cycles)
    out += _throughput(mean, policy, cycles, parts)
    return out


def reading_one_run(table: pd.DataFrame, policy: str, parts: int | None,
                     replications: pd.DataFrame | None = None) -> list[str]:
    """A policy published as one run (the adaptive one, §7.2): its IP against ours."""
    ad = table[table["policy"] == policy]
    cycle = float(ad["ideal_cycle_s"].iloc[0])

    def m(accounting: str, measure: str) -> Mapping[str, Any]:
        return row_of(table, policy, cycle, accounting, measure)

    ip_t, ip_w = m("thesis", "ip"), m("wallclock", "ip")
    lost_t, lost_w = m("thesis", "parts_missed"), m("wallclock", "parts_missed")
    cyc_t, cyc_w = m("thesis", "actual_cycle_s"), m("wallclock", "actual_cycle_s")
    ip_published = thesis_value(policy, cycle, "thesis", "ip")
    where = ("inside" if inside(ip_published, ip_t["run_p2_5"], ip_t["run_p97_5"], "ip")
             else "outside")
    text = [f"**{policy.capitalize()}.** In the thesis's accounting the IP averages {ip_t['mean']:.4f} "
            f"(single runs {ip_t['run_p2_5']:.4f}–{ip_t['run_p97_5']:.4f}): the published "
            f"{ip_published:.4f} is {where} that range."]
    if all(math.isfinite(v) for v in (cyc_t["mean"], cyc_w["mean"], ip_w["mean"])):
        text.append(
            f"Its time between deliveries is the robot's motion time (step 6.2), "
            f"{cyc_t['mean']:.2f} s, {cyc_t['mean'] / cycle - 1:+.2%} against the {cycle:.4f} s "
            f"requested; the published IP implies a motion time {1 / ip_published - 1:+.1%} "
            f"against the arrival interval. On the wall clock the cycle is {cyc_w['mean']:.2f} s "
            f"({cyc_w['mean'] / cycle - 1:+.2%}) and the IP {ip_w['mean']:.4f}.")
    text += memoryless(replications, ip_published, policy)
    text.append(
        f"Parts lost: {lost_w['mean']:.2f} per run on average "
        f"(95 % of runs {lost_w['run_p2_5']:.0f}–{lost_w['run_p97_5']:.0f}; the thesis: none)"
        + (f"; {lost_t['mean']:.2f} in the thesis's accounting." if
           lost_t["mean"] != lost_w["mean"] else "."))
    return [" ".join(text)]


def memoryless(replications: pd.DataFrame | None, ip_published: float,
                policy: str) -> list[str]:
    """The simulation's reading with each next arrival counted from the current pick-up."""
    cols = ("ip_thesis_memoryless", "cycle_vs_nominal_memoryless_pct")
    if replications is None or not all(c in replications for c in cols):
        return []
    ad = replications[replications["policy"] == policy]
    ip, pct = ad[cols[0]].astype(float), ad[cols[1]].astype(float)
    if ip.empty or not np.isfinite(ip).all():
        return []
    lo, hi = np.percentile(ip, [2.5, 97.5])
    where = "inside" if lo <= ip_published <= hi else "outside"
    return [f"Counted instead with each next arrival measured from the current pick-up, so that "
            f"a late part's lateness is not carried to the parts behind it, the IP is "
            f"{ip.mean():.4f} (single runs {lo:.4f}–{hi:.4f}; the published {ip_published:.4f} "
            f"is {where}) and the motion cycle {pct.mean():+.1f} % against the requested "
            f"(the thesis: within {published.ADAPTIVE_CYCLE_PCT} %)"
            + (": this reading reproduces the published IP, which suggests it is how the "
               "thesis counted." if where == "inside" else
               ": this reading does not reproduce the published IP either.")]
