"""``cell run SCENARIO --out DIR``: one run; DIR/parts.csv, summary.csv and belts.csv.

Part rows and belt changes are streamed to their files while the simulation
runs, so a long run needs little memory; the three files appear together.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

from cell.commands import scenario_arguments

if TYPE_CHECKING:
    from cell.records import RunSummary

HELP = "simulate one scenario; write parts.csv, summary.csv and belts.csv"
DESCRIPTION = "Run the cell in simulated time under the scenario's policy."


def add_arguments(p: argparse.ArgumentParser) -> None:
    scenario_arguments(p)
    p.add_argument("--out", required=True,
                   help="directory for parts.csv, summary.csv and belts.csv")


def format_summary(summary: RunSummary) -> str:
    """The summary as a two-column table, with the thesis's figures where it has them."""
    from cell import thesis as published

    adaptive = summary.policy == "adaptive"
    row = None if adaptive else published.TABLE_7_1.get(round(summary.ideal_cycle_s, 4))
    # the published figures as printed: four decimals, whole parts
    actual, missed, per_hr, vavg, ip = ((f"{x:.4f}" if isinstance(x, float) else f"{x}")
                                        for x in row) if row else ("",) * 5
    rows: list[tuple[str, str]] = []

    def add(label: str, value: Any, fmt: str = "{:.4f}", thesis: str = "") -> None:
        text = fmt.format(value) if isinstance(value, (int, float)) and value == value \
            else str(value)
        rows.append((label, text + (f"   (thesis: {thesis})" if thesis else "")))

    add("policy", summary.policy, "{}")
    add("ideal cycle, s", summary.ideal_cycle_s)
    add("parts arrived", summary.parts_arrived, "{:d}")
    add("parts delivered", summary.parts_delivered, "{:d}")
    add("parts lost (wall-clock)", summary.parts_missed, "{:d}", "0" if adaptive else missed)
    if not adaptive:
        add("parts lost (thesis bookkeeping)", summary.parts_missed_thesis, "{:d}", missed)
    add("actual cycle, wall-clock, s", summary.actual_cycle_wallclock_s)
    add("actual cycle, thesis's accounting, s", summary.actual_cycle_thesis_s, "{:.4f}", actual)
    add("parts/hr, wall-clock", summary.parts_per_hr_wallclock)
    add("parts/hr, thesis's accounting", summary.parts_per_hr_thesis, "{:.4f}", per_hr)
    add("Vavg R IV, in/s", summary.vavg_r4_in_s, "{:.4f}", vavg)
    add("IP, wall-clock", summary.ip_wallclock)
    add("IP, thesis's accounting", summary.ip_thesis, "{:.4f}",
        f"{published.ADAPTIVE_IP}" if adaptive else ip)
    if adaptive:
        add("mean cycle (step 6.2) vs 22.5872 s, %", summary.cycle_vs_nominal_pct,
            "{:+.2f}", f"within {published.ADAPTIVE_CYCLE_PCT} %")
        add("IP, arrivals counted from each pick-up", summary.ip_thesis_memoryless,
            "{:.4f}", f"{published.ADAPTIVE_IP}")
        add("mean cycle, same reading, %", summary.cycle_vs_nominal_memoryless_pct,
            "{:+.2f}", f"within {published.ADAPTIVE_CYCLE_PCT} %")
    add("spacing min / max, in",
        f"{summary.spacing_min_in:.3f} / {summary.spacing_max_in:.3f}", "{}", "45.00 ± 0.25")
    add("spacings outside tolerance", summary.spacing_outside_tol, "{:d}")
    add("parts with a note (limits hit, lost)", summary.parts_noted, "{:d}")
    width = max(len(label) for label, _ in rows)
    return "\n".join(f"{label:<{width}}  {text}" for label, text in rows)


#: The files of a run, written as one set.
RUN_FILES = ("parts.csv", "summary.csv", "belts.csv")


def main(args: argparse.Namespace) -> int:
    from cell.assembly import assemble
    from cell.csvfile import RowWriter
    from cell.output import OutputDir
    from cell.overrides import parse_sets
    from cell.records import BELT_COLUMNS, PART_COLUMNS, SUMMARY_COLUMNS
    from cell.scenario import load_scenario
    from cell.simulation import simulate

    OutputDir.check(args.out, RUN_FILES)  # before any work
    scenario = load_scenario(args.scenario, parse_sets(args.sets))
    cell = assemble(scenario)  # every error is raised before anything is written
    with OutputDir(args.out, RUN_FILES) as out:
        with out.open("parts.csv", newline="") as pf, out.open("belts.csv", newline="") as bf:
            parts, belts = RowWriter(pf, PART_COLUMNS), RowWriter(bf, BELT_COLUMNS)
            result = simulate(cell, keep_parts=False, on_part=parts.record,
                              on_belt=belts.record, keep_belts=False)
        with out.open("summary.csv", newline="") as sf:
            RowWriter(sf, SUMMARY_COLUMNS).record(result.summary)
    print(format_summary(result.summary))
    shown = out.target
    print(f"wrote {shown}/parts.csv, summary.csv and belts.csv")
    return 0
