"""Table 7.1 beside the thesis: ``cell sweep ... --report DIR`` (thesis §7.2; SPEC §8).

From the replications of a Table 7.1 sweep this writes

- ``table_7_1.csv``: long form, one row per (policy, ideal cycle, accounting,
  measure): the published value, the mean over replications with its 95 %
  confidence interval (Student t, scipy.stats), and the 2.5 and 97.5
  percentiles of single runs: the range a single 500-part run such as the
  thesis's should fall in.
- ``table_7_1.md``: the table in the thesis's layout with ours beside it, the
  adaptive results, and a reading generated from the numbers.

Two accountings of the same runs (SPEC §8): ``thesis`` reproduces the thesis's
bookkeeping, ``wallclock`` counts on the clock of a physically consistent cell.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
import scipy.stats

from cell import thesis as published
from cell.errors import CellError
from cell.output import write_csv, write_text

if TYPE_CHECKING:
    from cell.sweep import Sweep

COLUMNS = ["policy", "ideal_cycle_s", "accounting", "measure", "thesis",
           "mean", "ci_low", "ci_high", "run_p2_5", "run_p97_5"]
POLICIES = ("non-adaptive", "adaptive")
ACCOUNTINGS = ("thesis", "wallclock")
MEASURES = ("actual_cycle_s", "parts_missed", "parts_per_hr", "vavg_r4_in_s", "ip")
CONFIDENCE = 0.95
VARIED_KEY = "controller.ideal_cycle_s"

#: The adaptive run's published figures by measure (§7.2).
THESIS_ADAPTIVE = {"ip": published.ADAPTIVE_IP,
                   "parts_missed": float(published.ADAPTIVE_PARTS_MISSED)}

LABELS = {"actual_cycle_s": "actual cycle (s)", "parts_missed": "parts missed",
          "parts_per_hr": "parts/hr", "vavg_r4_in_s": "Vavg R IV (in/s)", "ip": "IP"}
DECIMALS = {"actual_cycle_s": 2, "parts_missed": 1, "parts_per_hr": 1,
            "vavg_r4_in_s": 4, "ip": 4}


def summary_column(accounting: str, measure: str, columns: Sequence[str]) -> str:
    """The summary column holding ``measure`` under ``accounting`` (issue 3's names).

    A measure both accountings share (Vavg R IV; parts missed unless the
    simulation splits it) is read from its one column.
    """
    candidates = {
        "actual_cycle_s": [f"actual_cycle_{accounting}_s"],
        "parts_missed": [f"parts_missed_{accounting}", "parts_missed"],
        "parts_per_hr": [f"parts_per_hr_{accounting}"],
        "vavg_r4_in_s": [f"vavg_r4_{accounting}_in_s", "vavg_r4_in_s"],
        "ip": [f"ip_{accounting}"],
    }[measure]
    for name in candidates:
        if name in columns:
            return name
    raise CellError(f"replications have no column {candidates[0]!r} for {measure} "
                    f"({accounting} accounting)")


def ideal_cycle(point: Any) -> float:
    """A point's robot cycle: ``controller.ideal_cycle_s``, else the nominal cycle."""
    c = point.scenario.controller
    return float(c.ideal_cycle_s if c.ideal_cycle_s is not None else c.nominal_cycle_s)


def check_table_7_1(sweep: Sweep) -> None:
    """Refuse, before anything runs, a sweep that --report cannot lay out as Table 7.1."""
    other = [k for k in sweep.keys if k != VARIED_KEY]
    if other:
        raise CellError(f"{sweep.source}: --report lays out Table 7.1, which varies only "
                        f"{VARIED_KEY}; this sweep also varies {', '.join(other)}")
    seen: set[tuple[str, float]] = set()
    for p in sweep.points:
        key = (p.policy, ideal_cycle(p))
        if key in seen:  # pragma: no cover - the grid rejects repeated values
            raise CellError(f"{sweep.source}: two {p.policy} points at ideal cycle {key[1]}")
        seen.add(key)


def thesis_value(policy: str, cycle: float, accounting: str, measure: str) -> float:
    """The published figure, or NaN; published figures are all in the thesis's accounting."""
    if accounting != "thesis":
        return math.nan
    if policy == "adaptive":
        return THESIS_ADAPTIVE.get(measure, math.nan)
    for c, row in published.TABLE_7_1.items():
        if abs(c - cycle) < 5e-5:
            return float(row[MEASURES.index(measure)])
    return math.nan


def statistics(values: Sequence[float] | np.ndarray) -> dict[str, float]:
    """Mean, its t confidence interval, and the 2.5/97.5 percentiles of single runs."""
    x = np.asarray(values, dtype=float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        nan = math.nan
        return {"mean": nan, "ci_low": nan, "ci_high": nan, "run_p2_5": nan, "run_p97_5": nan}
    mean = float(x.mean())
    sem = float(scipy.stats.sem(x)) if x.size > 1 else 0.0
    if sem > 0:
        lo, hi = scipy.stats.t.interval(CONFIDENCE, x.size - 1, loc=mean, scale=sem)
    else:
        lo = hi = mean
    p_lo, p_hi = np.percentile(x, [2.5, 97.5])
    return {"mean": mean, "ci_low": float(lo), "ci_high": float(hi),
            "run_p2_5": float(p_lo), "run_p97_5": float(p_hi)}


def table_7_1(replications: pd.DataFrame, sweep: Sweep) -> pd.DataFrame:
    """The long-form table: one row per (policy, ideal cycle, accounting, measure)."""
    rows = []
    order = sorted(range(len(sweep.points)),
                   key=lambda i: (POLICIES.index(sweep.points[i].policy), i))
    for i in order:
        p = sweep.points[i]
        runs = replications[(replications["policy"] == p.policy)
                            & (replications["point"] == p.index)]
        cycle = ideal_cycle(p)
        for accounting in ACCOUNTINGS:
            for measure in MEASURES:
                column = summary_column(accounting, measure, list(replications.columns))
                rows.append({"policy": p.policy, "ideal_cycle_s": cycle,
                             "accounting": accounting, "measure": measure,
                             "thesis": thesis_value(p.policy, cycle, accounting, measure),
                             **statistics(runs[column].to_numpy(dtype=float))})
    return pd.DataFrame(rows, columns=COLUMNS)


# --------------------------------------------------------------------------- markdown
def inside(thesis: float, low: float, high: float, measure: str) -> bool:
    """Whether a published figure lies in [low, high], to the thesis's printed precision
    (four decimals; parts missed are whole numbers)."""
    tol = 0.0 if measure == "parts_missed" else 0.5e-4
    return low - tol <= thesis <= high + tol


def _fmt(value: float, measure: str, decimals: int | None = None) -> str:
    if not math.isfinite(value):
        return ""
    return f"{value:.{DECIMALS[measure] if decimals is None else decimals}f}"


def _ours(row: Mapping[str, Any], measure: str) -> str:
    half = (row["ci_high"] - row["ci_low"]) / 2
    lo_hi = (f"{_fmt(row['run_p2_5'], measure, 0 if measure == 'parts_missed' else None)}–"
             f"{_fmt(row['run_p97_5'], measure, 0 if measure == 'parts_missed' else None)}")
    mark = ""
    thesis = row["thesis"]
    if math.isfinite(thesis) and not inside(thesis, row["run_p2_5"], row["run_p97_5"], measure):
        mark = " †"
    return f"{_fmt(row['mean'], measure)} ± {_fmt(half, measure)} [{lo_hi}]{mark}"


def _layout(table: pd.DataFrame, policy: str, accounting: str, with_thesis: bool) -> list[str]:
    sub = table[(table["policy"] == policy) & (table["accounting"] == accounting)]
    head = ["ideal cycle (s)"]
    for m in MEASURES:
        head += [f"{LABELS[m]}: thesis", "ours"] if with_thesis else [LABELS[m]]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for cycle, group in sub.groupby("ideal_cycle_s", sort=False):
        by: dict[str, Mapping[str, Any]] = {str(r["measure"]): {str(k): v for k, v in r.items()}
                                            for r in group.to_dict("records")}
        cells = [f"{cycle:.4f}"]
        for m in MEASURES:
            if with_thesis:
                cells.append(_fmt(by[m]["thesis"], m, 4 if m != "parts_missed" else 0))
            cells.append(_ours(by[m], m))
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def _get(table: pd.DataFrame, policy: str, cycle: float, accounting: str,
         measure: str) -> Mapping[str, Any]:
    sel = table[(table["policy"] == policy) & np.isclose(table["ideal_cycle_s"], cycle)
                & (table["accounting"] == accounting) & (table["measure"] == measure)]
    return {str(k): v for k, v in sel.iloc[0].to_dict().items()}


def reading(table: pd.DataFrame, parts: int | None,
            replications: pd.DataFrame | None = None) -> list[str]:
    """Sentences drawn from the numbers: agreement, where the accountings part, and why."""
    out: list[str] = []
    na = table[table["policy"] == "non-adaptive"]
    cycles = list(dict.fromkeys(na["ideal_cycle_s"]))
    if cycles:
        out += _reading_non_adaptive(table, cycles, parts)
    if (table["policy"] == "adaptive").any():
        out += _reading_adaptive(table, replications)
    return out


def _cycles(cycles: Sequence[float]) -> str:
    text = [f"{c:.4f}" if c != round(c, 1) else f"{c:.1f}" for c in cycles]
    return ", ".join(text[:-1]) + " and " + text[-1] if len(text) > 1 else text[0]


def _reading_non_adaptive(table: pd.DataFrame, cycles: list[float],
                          parts: int | None) -> list[str]:
    out = []
    mean = {(c, a, m): _get(table, "non-adaptive", c, a, m)["mean"]
            for c in cycles for a in ACCOUNTINGS for m in MEASURES}
    checked, outside = 0, []
    for c in cycles:
        for m in ("parts_missed", "actual_cycle_s", "ip"):
            r = _get(table, "non-adaptive", c, "thesis", m)
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
    vrows = [_get(table, "non-adaptive", c, "thesis", "vavg_r4_in_s") for c in cycles]
    vv = [abs(r["mean"] - r["thesis"]) for r in vrows if math.isfinite(r["thesis"])]
    if vv:
        fixed = all(r["run_p2_5"] == r["run_p97_5"] for r in vrows)
        out.append(f"Vavg R IV differs from the published column by at most {max(vv):.5f} in/s"
                   + (" (the R IV length over the shortened R IV time: the same in every run)."
                      if fixed else "."))

    top, bottom = cycles[0], cycles[-1]
    tm, wm = mean[top, "thesis", "parts_missed"], mean[top, "wallclock", "parts_missed"]
    ta, wa = mean[top, "thesis", "actual_cycle_s"], mean[top, "wallclock", "actual_cycle_s"]
    tb, wb = mean[bottom, "thesis", "actual_cycle_s"], mean[bottom, "wallclock", "actual_cycle_s"]
    tmb, wmb = mean[bottom, "thesis", "parts_missed"], mean[bottom, "wallclock", "parts_missed"]
    of = f" of {parts}" if parts else ""
    gap_top, gap_bottom = ta / wa - 1, tb / wb - 1
    trend = ("narrows as the cycle shortens and losses grow rare"
             if abs(gap_bottom) < abs(gap_top) else "widens as the cycle shortens")
    out.append(
        f"**Where the accountings part.** At {top:.4f} s the thesis's bookkeeping loses "
        f"{tm:.1f}{of} parts on average against {wm:.1f} on the wall clock, and its actual "
        f"cycle is {ta:.2f} s against {wa:.2f} s ({gap_top:+.1%}). At {bottom:.4f} s it is "
        f"{tmb:.1f} against {wmb:.1f} parts and {tb:.2f} against {wb:.2f} s "
        f"({gap_bottom:+.1%}): the gap {trend}.")
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
    ratios = [mean[c, "wallclock", "ip"] / mean[c, "thesis", "ip"] for c in cycles
              if mean[c, "thesis", "ip"] > 0]
    if ratios:
        out.append(
            f"IP: the thesis's column averages T(i+1) / (2 D(i)), a doubled denominator, so it "
            f"reads {min(ratios):.2f}–{max(ratios):.2f} times lower than the wall-clock IP "
            f"({mean[top, 'thesis', 'ip']:.4f} against {mean[top, 'wallclock', 'ip']:.4f} at "
            f"{top:.4f} s, {mean[bottom, 'thesis', 'ip']:.4f} against "
            f"{mean[bottom, 'wallclock', 'ip']:.4f} at {bottom:.4f} s).")
    ideal_pph = 3600 / top
    cut_t = 1 - mean[top, "thesis", "parts_per_hr"] / ideal_pph
    cut_w = 1 - mean[top, "wallclock", "parts_per_hr"] / ideal_pph
    thesis_row = published.TABLE_7_1.get(round(top, 4))
    if thesis_row and parts:
        out.append(
            f"Throughput at {top:.4f} s: the thesis's accounting gives "
            f"{mean[top, 'thesis', 'parts_per_hr']:.1f} parts/hr, {cut_t:.0%} below the "
            f"{ideal_pph:.1f}/hr of the ideal cycle (the thesis's table: "
            f"{1 - thesis_row[2] / ideal_pph:.0%}), while {tm / parts:.1%} of the parts are lost "
            f"(the thesis's text: {published.TEXT_THROUGHPUT_CUT:.1%}, 206 of 500): the table's parts/hr and "
            f"the text's throughput cut measure different things. On the wall clock the cut is "
            f"{cut_w:.0%}.")
    return out


def _reading_adaptive(table: pd.DataFrame,
                      replications: pd.DataFrame | None = None) -> list[str]:
    ad = table[table["policy"] == "adaptive"]
    cycle = float(ad["ideal_cycle_s"].iloc[0])

    def m(accounting: str, measure: str) -> Mapping[str, Any]:
        return _get(table, "adaptive", cycle, accounting, measure)

    ip_t, ip_w = m("thesis", "ip"), m("wallclock", "ip")
    lost_t, lost_w = m("thesis", "parts_missed"), m("wallclock", "parts_missed")
    cyc_t, cyc_w = m("thesis", "actual_cycle_s"), m("wallclock", "actual_cycle_s")
    ip_published = THESIS_ADAPTIVE["ip"]
    where = ("inside" if inside(ip_published, ip_t["run_p2_5"], ip_t["run_p97_5"], "ip")
             else "outside")
    text = [f"**Adaptive.** In the thesis's accounting the IP averages {ip_t['mean']:.4f} "
            f"(single runs {ip_t['run_p2_5']:.4f}–{ip_t['run_p97_5']:.4f}): the published "
            f"{ip_published:.4f} is {where} that range."]
    if all(math.isfinite(v) for v in (cyc_t["mean"], cyc_w["mean"], ip_w["mean"])):
        text.append(
            f"Its time between deliveries is the robot's motion time (step 6.2), "
            f"{cyc_t['mean']:.2f} s, {cyc_t['mean'] / cycle - 1:+.2%} against the {cycle:.4f} s "
            f"requested; the published IP implies a motion time {1 / ip_published - 1:+.1%} "
            f"against the arrival interval. On the wall clock the cycle is {cyc_w['mean']:.2f} s "
            f"({cyc_w['mean'] / cycle - 1:+.2%}) and the IP {ip_w['mean']:.4f}.")
    text += _memoryless(replications, ip_published)
    text.append(
        f"Parts lost: {lost_w['mean']:.2f} per run on average "
        f"(95 % of runs {lost_w['run_p2_5']:.0f}–{lost_w['run_p97_5']:.0f}; the thesis: none)"
        + (f"; {lost_t['mean']:.2f} in the thesis's accounting." if
           lost_t["mean"] != lost_w["mean"] else "."))
    return [" ".join(text)]


def _memoryless(replications: pd.DataFrame | None, ip_published: float) -> list[str]:
    """The simulation's reading with each next arrival counted from the current pick-up."""
    cols = ("ip_thesis_memoryless", "cycle_vs_nominal_memoryless_pct")
    if replications is None or not all(c in replications for c in cols):
        return []
    ad = replications[replications["policy"] == "adaptive"]
    ip, pct = ad[cols[0]].astype(float), ad[cols[1]].astype(float)
    if ip.empty or not np.isfinite(ip).all():
        return []
    lo, hi = np.percentile(ip, [2.5, 97.5])
    where = "inside" if lo <= ip_published <= hi else "outside"
    return [f"Counted instead with each next arrival measured from the current pick-up, so that "
            f"a late part's lateness is not carried to the parts behind it, the IP is "
            f"{ip.mean():.4f} (single runs {lo:.4f}–{hi:.4f}; the published {ip_published:.4f} "
            f"is {where}) and the motion cycle {pct.mean():+.1f} % against the requested "
            f"(the thesis: within 2.1 %)"
            + (": this reading reproduces the published IP, which suggests it is how the "
               "thesis counted." if where == "inside" else
               ": this reading does not reproduce the published IP either.")]


def markdown(table: pd.DataFrame, sweep: Sweep, replications: pd.DataFrame | None = None) -> str:
    parts = sweep.points[0].scenario.run.parts if sweep.points else None
    lines = [
        "# Table 7.1 regenerated (thesis §7.2)",
        "",
        f"Generated by `cell sweep {sweep.source} --report ...` from "
        f"{sweep.replications} replications of {parts} parts per row, root seed {sweep.seed}; "
        "every row and both policies see the same arrivals (common random numbers). "
        "Numbers: our mean ± half-width of its 95 % confidence interval (Student t), "
        "[the 2.5–97.5 % range of single runs: where one run like the thesis's should fall]. "
        "† marks a published figure outside that range. "
        "Long form with every figure: `table_7_1.csv`.",
        "",
    ]
    if (table["policy"] == "non-adaptive").any():
        lines += ["## Non-adaptive, the thesis's accounting (its Table 7.1 beside ours)", ""]
        lines += _layout(table, "non-adaptive", "thesis", with_thesis=True)
        lines += ["", "## Non-adaptive, on the wall clock (a physically consistent count)", ""]
        lines += _layout(table, "non-adaptive", "wallclock", with_thesis=False)
        lines += [""]
    if (table["policy"] == "adaptive").any():
        lines += ["## Adaptive (thesis §7.2: IP 1.0214, within 2.1 % of the requested cycle, "
                  "no parts lost)", ""]
        head = ["accounting"] + [LABELS[m] for m in MEASURES]
        lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        ad = table[table["policy"] == "adaptive"]
        cycle = float(ad["ideal_cycle_s"].iloc[0])
        published_cells = [_fmt(thesis_value("adaptive", cycle, "thesis", m), m,
                          0 if m == "parts_missed" else 4) for m in MEASURES]
        lines.append("| thesis (published) | " + " | ".join(published_cells) + " |")
        for accounting in ACCOUNTINGS:
            cells = [_ours(_get(table, "adaptive", cycle, accounting, m), m) for m in MEASURES]
            lines.append(f"| ours, {accounting} | " + " | ".join(cells) + " |")
        lines += [""]
    lines += ["## Reading", ""]
    for sentence in reading(table, parts, replications):
        lines += [sentence, ""]
    return "\n".join(lines).rstrip() + "\n"


def write_table_7_1(replications: pd.DataFrame, sweep: Sweep, out: str | Path) -> list[Path]:
    """Write ``table_7_1.csv`` and ``table_7_1.md`` into ``out``; return their paths."""
    out = Path(out)
    table = table_7_1(replications, sweep)
    text = markdown(table, sweep, replications)
    paths = [out / "table_7_1.csv", out / "table_7_1.md"]
    write_csv(table, paths[0])
    write_text(text, paths[1])
    return paths
