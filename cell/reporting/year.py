"""The worked year (``make year``; issue 33 item 6): the thesis's cell on a plant's calendar.

From ``scenarios/year.yaml`` (two eight-hour shifts five days a week, 52 weeks, the robot and
the belts failing on the working clock, arrivals 20 % faster in each shift's first two hours)
this runs both policies with the repair crew as the scenario has it (both shifts) and on the
first shift only, ``--replications`` years each, replication r drawing the same parts and
the same failures everywhere (common random numbers), and writes as one set

- ``runs.csv``: every run's OEE (ISO 22400-2, :mod:`cell.sim.oee`) and losses, shift by shift
  of the day and over the whole year;
- ``shifts.csv``: the OEE table, one row per policy, crew and shift of the day, means over the
  years with 95 % t intervals;
- ``crews.csv``: what the second shift's crew is worth, the paired difference (both shifts −
  first shift only) in parts delivered a year, OEE and downtime, per policy;
- ``year.png``: OEE and its losses per shift of the day, per crew and policy;
- ``report.md``: the headline and a reading generated from those numbers, and the tables.

A shift's figures are the work unit's (the robot's) over that shift's working time: its
planned busy time is the shift's working time on the run's working days, its produced
quantity the parts set down in it; the quality rule is the scenario's (every part set down is
good by default).  The whole year's row is the run's summary.

``python -m cell.reporting.year SCENARIO REPORT_DIR [--workers N] [--replications R]``.
"""

from __future__ import annotations

import argparse
import io
import math
from array import array
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cell.experiments.stats import paired_difference, summarise
from cell.plumbing.csvfile import FLOAT_FORMAT
from cell.plumbing.output.atomic import OutputDir

FILES = ("report.md", "runs.csv", "shifts.csv", "crews.csv", "year.png")
POLICIES = ("adaptive", "non-adaptive")
#: The crews compared: the scenario's hours (both shifts), and the first shift only.
CREWS = ("both shifts", "first shift")
SAID = {"both shifts": "a crew on both shifts", "first shift": "a crew on the first shift only"}
MEASURES = ("oee", "availability", "performance", "quality", "loss_downtime", "loss_starved",
            "loss_blocked", "loss_speed", "loss_quality")
COUNTS = ("parts_delivered", "parts_lost", "down_h")


def crew_overrides(s: Any, crew: str) -> dict[str, Any]:
    """The scenario's crew (``both shifts``) or one on its first shift only."""
    if crew == CREWS[0]:
        return {}
    return {"failures.repair.hours": [list(s.calendar.shifts[0])]}


def one_year(path: str, policy: str, crew: str, replication: int) -> list[dict[str, Any]]:
    """One run (a year): its rows of ``runs.csv``, shift by shift and the whole year."""
    from cell.scenario.calendar_section import working_week
    from cell.scenario.schema import load_scenario
    from cell.sim import oee
    from cell.sim.simulation import simulate

    base = load_scenario(path)
    s = load_scenario(path, {"controller.policy": policy, **crew_overrides(base, crew)})
    set_down, lost = array("d"), array("d")

    def told(record: Any) -> None:
        if record.touchdown_s == record.touchdown_s:
            set_down.append(record.touchdown_s)
        if record.missed:
            lost.append(record.arrival_s)

    seed = np.random.SeedSequence(s.run.seed, spawn_key=(replication,))
    result = simulate(s, seed, keep_parts=False, keep_belts=False, on_part=told)
    r, cal = result.summary, s.calendar
    if cal is None:
        raise ValueError(f"{path}: the worked year needs a calendar: section")
    end = r.sim_end_s
    t_down, t_lost = np.frombuffer(set_down), np.frombuffer(lost)
    rows = []
    shifts = [(f"{i + 1} ({a}-{b})", [(a, b)]) for i, (a, b) in enumerate(cal.shifts)]
    for name, hours in [*shifts, ("all", None)]:
        week = working_week(cal, s.source, hours, "calendar.shifts")
        off = week.gaps(0.0, end)
        seconds = oee.unit_seconds(None, result.downtime, end,  # type: ignore[arg-type]
                                   result.stop_rows, [off])
        made = int(np.count_nonzero(week.inside(t_down)))
        figures = oee.oee_figures(seconds, r.nominal_cycle_s, made, made)
        rows.append({"policy": policy, "crew": crew, "replication": replication, "shift": name,
                     "working_h": float(week.measure(end)) / 3600.0,
                     "parts_delivered": made,
                     "parts_lost": int(np.count_nonzero(week.inside(t_lost))),
                     "down_h": seconds["down"] / 3600.0,
                     **{m: figures[m] for m in MEASURES}})
    return rows


def run_all(path: str, replications: int, workers: int) -> pd.DataFrame:
    """Every (policy, crew, replication) year, in that order, ``workers`` at once."""
    tasks = [(path, p, c, k) for p in POLICIES for c in CREWS for k in range(replications)]
    if workers <= 1:
        done = [one_year(*t) for t in tasks]
    else:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            done = list(pool.map(one_year, *zip(*tasks)))
    return pd.DataFrame([row for rows in done for row in rows])


def shift_table(runs: pd.DataFrame) -> pd.DataFrame:
    """One row per policy, crew and shift: each measure's mean over the years, with its 95 %
    t interval for OEE and the parts delivered."""
    out = []
    for (policy, crew, shift), g in runs.groupby(["policy", "crew", "shift"], sort=False):
        row: dict[str, Any] = {"policy": policy, "crew": crew, "shift": shift,
                               "replications": len(g), "working_h": g["working_h"].mean()}
        for m in (*MEASURES, *COUNTS):
            row[m] = float(g[m].mean())
        for m in ("oee", "parts_delivered"):
            ci = summarise(g[m].to_numpy())
            row[f"{m}_ci_low"], row[f"{m}_ci_high"] = ci["ci_low"], ci["ci_high"]
        out.append(row)
    return pd.DataFrame(out)


def crew_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Per policy: the paired difference, crew on both shifts less crew on the first only,
    over the whole year (replication r against replication r)."""
    year = runs[runs["shift"] == "all"]
    out = []
    for policy in POLICIES:
        mine = year[year["policy"] == policy]
        both = mine[mine["crew"] == CREWS[0]].sort_values("replication")
        first = mine[mine["crew"] == CREWS[1]].sort_values("replication")
        for m in ("parts_delivered", "oee", "down_h", "parts_lost"):
            d = paired_difference(both[m].to_numpy(), first[m].to_numpy())
            out.append({"policy": policy, "measure": m, "both_shifts": float(both[m].mean()),
                        "first_shift": float(first[m].mean()), "difference": d["mean"],
                        "ci_low": d["ci_low"], "ci_high": d["ci_high"]})
    return pd.DataFrame(out)


def _row(t: pd.DataFrame, **keys: Any) -> pd.Series:
    for k, v in keys.items():
        t = t[t[k] == v]
    return t.iloc[0]


def headline(shifts: pd.DataFrame, crews: pd.DataFrame) -> str:
    """The report's first paragraph, every number from the tables."""
    a = _row(shifts, policy="adaptive", crew=CREWS[0], shift="all")
    n = _row(shifts, policy="non-adaptive", crew=CREWS[0], shift="all")
    worth = _row(crews, policy="adaptive", measure="parts_delivered")
    worth_oee = _row(crews, policy="adaptive", measure="oee")
    return (
        f"Over a year of two shifts ({a['working_h']:,.0f} working hours, {a['replications']:.0f} "
        f"years a configuration), the adaptive robot's OEE is {a['oee']:.3f} "
        f"(95 % CI {a['oee_ci_low']:.3f}–{a['oee_ci_high']:.3f}) against {n['oee']:.3f} for the "
        f"fixed cycle, {a['parts_delivered'] - n['parts_delivered']:,.0f} more parts a year "
        f"({a['parts_delivered']:,.0f} against {n['parts_delivered']:,.0f}). A repair crew on "
        f"the second shift as well as the first is worth {worth['difference']:,.0f} parts a year "
        f"to the adaptive robot (95 % CI {worth['ci_low']:,.0f} to {worth['ci_high']:,.0f}) and "
        f"{100 * worth_oee['difference']:.1f} points of OEE.")


def reading(shifts: pd.DataFrame, crews: pd.DataFrame) -> list[str]:
    """What the per-shift table says, in sentences made from it."""
    lines = []
    names = [s for s in shifts["shift"].unique() if s != "all"]
    for policy in POLICIES:
        for crew in CREWS:
            rows = [_row(shifts, policy=policy, crew=crew, shift=s) for s in names]
            worst = min(rows, key=lambda r: r["oee"])
            best = max(rows, key=lambda r: r["oee"])
            losses = {m: worst[m] for m in MEASURES if m.startswith("loss_")}
            biggest = max(losses, key=lambda m: losses[m])
            lines.append(
                f"- {policy}, {SAID[crew]}: shift {best['shift']} OEE {best['oee']:.3f}, shift "
                f"{worst['shift']} {worst['oee']:.3f}; the weaker shift's largest loss is "
                f"{biggest} ({worst[biggest]:.3f} of its planned busy time; downtime "
                f"{worst['loss_downtime']:.3f} against {best['loss_downtime']:.3f}).")
    saved = [_row(crews, policy=p, measure="down_h") for p in POLICIES]
    alike = len({round(d["difference"], 6) for d in saved}) == 1
    for policy, d in zip(POLICIES, saved[:1] if alike else saved):
        who = "both policies alike (the failure clocks count working time, not motion, and " \
            "both policies draw the same failures)" if alike else policy
        first = [_row(shifts, policy=policy, crew=c, shift=names[0]) for c in CREWS]
        lines.append(f"- The second shift's crew saves {-d['difference']:.1f} hours of the "
                     f"robot's downtime in working time a year (95 % CI {-d['ci_high']:.1f} to "
                     f"{-d['ci_low']:.1f}), for {who}. Without it a failure in the second "
                     f"shift waits for the next morning's crew, so the first shift carries "
                     f"those repairs: its downtime is {first[1]['loss_downtime']:.3f} of its "
                     f"planned busy time against {first[0]['loss_downtime']:.3f} with both crews.")
    return lines


def figure(shifts: pd.DataFrame, path: Path) -> None:
    """OEE and its losses stacked, per shift of the day, crew and policy."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    parts = ("oee", "loss_downtime", "loss_starved", "loss_blocked", "loss_speed", "loss_quality")
    colours = ("#2a7", "#c33", "#f93", "#963", "#99c", "#777")
    fig, axes = plt.subplots(1, len(POLICIES), figsize=(11, 4.2), sharey=True)
    for ax, policy in zip(axes, POLICIES):
        rows = shifts[(shifts["policy"] == policy) & (shifts["shift"] != "all")]
        labels = [f"{r['crew']}\nshift {r['shift'].split()[0]}" for _, r in rows.iterrows()]
        x = np.arange(len(rows))
        bottom = np.zeros(len(rows))
        for part, colour in zip(parts, colours):
            h = np.maximum(rows[part].to_numpy(), 0.0)
            ax.bar(x, h, bottom=bottom, color=colour, label=part)
            bottom += h
        ax.set_xticks(x, labels, fontsize=8)
        ax.set_title(policy)
        ax.set_ylim(0, 1.05)
    axes[0].set_ylabel("share of the planned busy time")
    axes[-1].legend(fontsize=7, loc="lower right")
    fig.suptitle("OEE and its losses by shift (ISO 22400-2), a year of two shifts; a negative "
                 "loss_speed (faster than the nominal cycle) is not drawn", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110, metadata={"Software": None})
    plt.close(fig)


def _markdown(frame: pd.DataFrame, columns: Sequence[str]) -> str:
    head = "| " + " | ".join(columns) + " |\n|" + "---|" * len(columns) + "\n"
    def cell(v: Any) -> str:
        if isinstance(v, float):
            return "" if math.isnan(v) else f"{v:,.0f}" if abs(v) >= 100 else f"{v:.3f}"
        return str(v)
    return head + "".join("| " + " | ".join(cell(r[c]) for c in columns) + " |\n"
                          for _, r in frame.iterrows())


def report(shifts: pd.DataFrame, crews: pd.DataFrame, scenario: str, seconds: float | None
           ) -> str:
    table = shifts[["policy", "crew", "shift", "oee", "oee_ci_low", "oee_ci_high",
                    "availability", "performance", "quality", *[m for m in MEASURES
                                                                if m.startswith("loss_")],
                    "parts_delivered", "parts_lost"]]
    return "\n".join([
        "# A worked year on a shift calendar", "",
        f"`make year`: `{scenario}` (docs/usage.md, \"A shift calendar\"), both policies, the "
        "repair crew on both shifts and on the first shift only. Every number below is "
        "generated from `shifts.csv` and `crews.csv`.", "",
        headline(shifts, crews), "",
        "## OEE and its losses by shift of the day", "",
        "Each shift's row is the robot's time over that shift's working time on the working "
        "days (ISO 22400-2: planned busy time less downtime, starved and blocked is the actual "
        "production time; `cell docs model`, \"OEE as plants define it\"); `all` is the year. "
        "Means over the years; OEE with its 95 % t interval.", "",
        _markdown(table, list(table.columns)), "",
        *reading(shifts, crews), "",
        "![OEE and losses by shift](year.png)", "",
        "## What the second shift's crew is worth", "",
        "Paired over the same years (common random numbers): both shifts less the first only.",
        "",
        _markdown(crews, list(crews.columns)), "",
        "## Assumed", "",
        "The failure and repair profile is assumed, not measured: the robot fails after a "
        "Weibull time (mean 40 working hours, shape 1.5) and is repaired in a lognormal time "
        "(mean 1.5 h, coefficient of variation 1); each belt after a Weibull 160 h (shape 1.2), "
        "repaired in a lognormal 0.75 h (cv 0.8); one crew. Arrivals are eq. 6.9's, 20 % "
        "faster in each shift's first two working hours than in the rest (normalised: the "
        "long-run mean inter-arrival time stays 22.586 s).",
        *([] if seconds is None else ["", f"Made in {seconds / 60:.0f} minutes on this machine."]),
        ""])


def main(argv: Sequence[str] | None = None) -> int:
    import time

    p = argparse.ArgumentParser(prog="python -m cell.reporting.year")
    p.add_argument("scenario")
    p.add_argument("out")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--replications", type=int, default=3)
    p.add_argument("--runs", help="a runs.csv already made: the report from it, no run")
    args = p.parse_args(argv)
    OutputDir.check(args.out, FILES, option="REPORT_DIR")
    start = time.monotonic()
    if args.runs:
        runs = pd.read_csv(args.runs)
    else:  # as runs.csv will hold them, so that the tables are the file's, to the bit
        made = run_all(args.scenario, args.replications, args.workers)
        runs = pd.read_csv(io.StringIO(made.to_csv(index=False, float_format=FLOAT_FORMAT)))
    shifts, crews = shift_table(runs), crew_table(runs)
    with OutputDir(args.out, FILES, option="REPORT_DIR") as out:
        out.write_csv("runs.csv", runs)
        out.write_csv("shifts.csv", shifts)
        out.write_csv("crews.csv", crews)
        figure(shifts, out.path("year.png"))
        out.write_text("report.md", report(shifts, crews, args.scenario, None))
    print(headline(shifts, crews))
    print(f"wrote {args.out} in {time.monotonic() - start:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
