"""``cell run SCENARIO --out DIR``: one run; DIR/parts.csv, summary.csv and belts.csv.

Part rows and belt changes are streamed to their files while the simulation
runs, so a long run needs little memory; the three files appear together.  A
long run shows its progress on stderr.  A DIR that holds another run's files is
refused (exit 2, its files untouched) unless ``--force``; ``--format parquet``
writes the three as Parquet (:mod:`cell.plumbing.output.parquet`).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from typing import Any

from cell.cli.common import scenario_arguments, scenario_of

HELP = "simulate one scenario; write parts.csv, summary.csv and belts.csv"
DESCRIPTION = "Run the cell in simulated time under the scenario's policy."


def add_arguments(p: argparse.ArgumentParser) -> None:
    scenario_arguments(p)
    p.add_argument("--out", required=True,
                   help="directory for parts.csv, summary.csv and belts.csv")
    p.add_argument("--force", action="store_true",
                   help="replace the files of a run already in --out")
    p.add_argument("--format", choices=("csv", "parquet"), default="csv",
                   help="write the three files as CSV (default) or Parquet")
    p.add_argument("--thesis", action="store_true",
                   help="print the thesis's accounting (IP, R IV, its bookkeeping) after the "
                        "plant's measures (a thesis scenario prints it unasked)")


#: The files of a run, written as one set.
RUN_FILES = ("parts.csv", "summary.csv", "belts.csv")
#: Written as well when the scenario has a ``failures:`` section or its motors wear.
FAILURE_FILES = ("states.csv", "failures.csv")
#: The same, as ``--format parquet`` writes them.
PARQUET_FILES = ("parts.parquet", "summary.parquet", "belts.parquet")
#: Runs of at least this many parts (or, with ``run.hours``, expected parts) show their
#: progress on stderr (a bar on a terminal, a line every tenth of the run in a log).
PROGRESS_FROM_PARTS = 50_000


def main(args: argparse.Namespace) -> int:
    from cell.plumbing.csvfile import RowWriter
    from cell.plumbing.output.atomic import OutputDir
    from cell.plumbing.progress import Progress
    from cell.reporting.run_summary import run_heading
    from cell.reporting.unit_slips import run_warnings
    from cell.scenario.run_length import expected_parts
    from cell.scenario.schema import inert_settings
    from cell.sim.assembly import assemble
    from cell.sim.records import BELT_COLUMNS
    from cell.sim.sim_result import part_columns, station_columns, stops_anything, writes_states
    from cell.sim.simulation import simulate

    names = RUN_FILES + FAILURE_FILES + PARQUET_FILES + ("stations.csv",)
    OutputDir.check(args.out, names)  # before any work
    _refuse_a_run(args)
    scenario = scenario_of(args)
    cell = assemble(scenario)  # every error is raised before anything is written
    print(run_heading(cell))
    timed = scenario.robot.timing == "minimum-time"  # the planner's settings matter
    if timed:
        from cell.reporting.planner_report import planner_line
        print(planner_line(scenario))
    for line in [*run_warnings(cell), *(inert_settings(scenario) if timed else [])]:
        print(f"cell: warning: {line}", file=sys.stderr)
    n = round(expected_parts(scenario))  # run.hours: about that many
    with OutputDir(args.out, names) as out, \
            Progress(n, "cell run", "parts", enabled=n >= PROGRESS_FROM_PARTS) as progress:
        with out.open("parts.csv", newline="") as pf, out.open("belts.csv", newline="") as bf:
            parts = RowWriter(pf, part_columns(cell))
            belts = RowWriter(bf, BELT_COLUMNS)
            result = simulate(cell, keep_parts=False, on_part=_on_part(parts, progress, n, scenario),
                              on_belt=belts.record, keep_belts=False)
            done = result.summary.parts_arrived if scenario.run.hours is not None else n
            progress.grow(done - progress.total)
            progress.update(done - progress.n)
        with out.open("summary.csv", newline="") as sf:
            RowWriter(sf, list(result.summary.as_dict())).record(result.summary)
        if result.station_rows is not None:  # buffer: or stations: (docs/layout.md)
            with out.open("stations.csv", newline="") as f:
                write = RowWriter(f, station_columns(scenario)).record
                for row in result.station_rows:
                    write(row)
        if writes_states(scenario):
            _write_failures(out, result, stops_anything(scenario), scenario)
        if args.format == "parquet":
            _as_parquet(out)
    _report(args, scenario, result, out.target)
    return 0


def _on_part(parts: Any, progress: Any, n: int, scenario: Any) -> Callable[[Any], None]:
    """What each part's record goes to: its row in parts.csv (with its timestamp under a
    calendar) and, on a run that shows its progress, the count (in chunks: a call per part
    would show in the run's time)."""
    from cell.sim.calendar import stamped

    write = stamped(scenario, parts.record)
    if not progress.enabled:
        return write
    step = max(1, n // 200)

    def counted(record: Any) -> None:
        write(record)
        if record.part % step == 0:
            progress.update(step)

    return counted


def _report(args: argparse.Namespace, scenario: Any, result: Any, shown: str) -> None:
    """The run's summary on stdout: the plant's measures first (throughput, OEE and its
    losses, parts lost), the thesis's accounting when asked for or for a thesis scenario;
    the stops with failures; the files written."""
    from cell.reporting.run_summary import (
        format_summary,
        shows_thesis,
        stops_line,
        thesis_figures,
    )
    from cell.sim.sim_result import stops_anything, writes_states

    accounting = shows_thesis(scenario, args.thesis)
    r = result.summary
    print(format_summary(r, thesis_figures(scenario) if accounting else None, accounting))
    print(f"robot busy (in motion) {r.robot_busy_fraction:.3f} of the run, beside its offered "
          f"load (fastest cycle / mean inter-arrival) {r.offered_load:.3f}")
    written = RUN_FILES if args.format == "csv" else PARQUET_FILES
    if not stops_anything(scenario):
        also = ", states.csv" if writes_states(scenario) else ""
        also += ", stations.csv" if result.station_rows is not None else ""
        print(f"wrote {shown}/{written[0]}, {written[1]}{also} and {written[2]}")
        return
    print(stops_line(r, scenario.failures))
    if result.station_rows is not None:  # the line above is the first station's
        print("down, share of the run: " + ", ".join(
            f"{row.station} {row.down_fraction:.3f}" for row in result.station_rows))
    also = ", stations.csv" if result.station_rows is not None else ""
    print(f"wrote {shown}/{written[0]}, {written[1]}, {written[2]}{also}, states.csv and failures.csv")


def _write_failures(out: Any, result: Any, stops: bool, scenario: Any) -> None:
    """states.csv, and failures.csv of a run with failures or wear (``stops``) at any station
    (each row naming its station in a layout); under a calendar each row's ends also as
    timestamps."""
    from cell.plumbing.csvfile import RowWriter
    from cell.sim.calendar import dated
    from cell.sim.records import STATE_COLUMNS, STOP_COLUMNS
    from cell.sim.sim_result import named_columns

    for name, columns, rows in (("states.csv", STATE_COLUMNS, result.state_spans()),
                                ("failures.csv", STOP_COLUMNS, result.stops() if stops else None)):
        if rows is None:
            continue
        times, rows = dated(scenario, rows)
        with out.open(name, newline="") as f:
            write = RowWriter(f, named_columns(result, columns) + times).record
            for row in rows:
                write(row)


def _refuse_a_run(args: argparse.Namespace) -> None:
    """A DIR holding a run's files (either format) is refused unless ``--force``."""
    import os

    from cell.plumbing.errors import CellError

    if args.force:
        return
    found = [n for n in RUN_FILES + PARQUET_FILES if os.path.lexists(os.path.join(args.out, n))]
    if found:
        raise CellError(f"{args.out}: holds another run's files ({', '.join(found)}); "
                        "--force replaces them, or choose another --out")


def _as_parquet(out: Any) -> None:
    """The staged CSV files as Parquet, in their place (:mod:`cell.plumbing.output.parquet`)."""
    import os

    from cell.plumbing.output.parquet import csv_to_parquet, parquet_name

    for name in RUN_FILES:
        csv_to_parquet(out.path(name), out.path(parquet_name(name)))
        os.remove(out.path(name))
