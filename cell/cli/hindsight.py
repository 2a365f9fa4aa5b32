"""``cell hindsight SCENARIO --out DIR``: the hindsight optimum of the scenario's run.

For the parts the run sees (its arrivals and ``run.seed``, drawn as ``cell run`` draws them),
the most any feasible schedule could deliver: a MILP's proved bound and a schedule found by
search and run through the simulation (:mod:`cell.experiments.hindsight`).  DIR/schedule.csv
is the schedule, part by part; DIR/summary.csv has ``parts_optimum``, ``exact``,
``parts_upper``, ``parts_bound`` and the times taken.  Both appear together or not at all.
"""

from __future__ import annotations

import argparse
import math
import sys

from cell.cli.common import scenario_arguments, scenario_of

HELP = "the most parts any schedule could deliver from a run's arrivals; write schedule.csv " \
       "and summary.csv"
DESCRIPTION = ("The hindsight optimum of one run: a MILP's proved bound (HiGHS, for runs of "
               "tens of parts) and a schedule that knows the arrivals, run through the "
               "simulation; exact where they meet.")

#: The files written, as one set.
FILES = ("schedule.csv", "summary.csv")


#: The time budget of one run's hindsight (s), unless ``--budget`` says.
BUDGET_S = 60.0


def add_arguments(p: argparse.ArgumentParser) -> None:
    scenario_arguments(p)
    p.add_argument("--out", required=True, help="directory for schedule.csv and summary.csv")
    p.add_argument("--budget", type=float, default=BUDGET_S, metavar="S",
                   help=f"seconds the run's hindsight may take (default {BUDGET_S:g}): the MILP "
                        "gets most of it; stopped, it gives its bound unproved (exact=false)")


def main(args: argparse.Namespace) -> int:
    from cell.experiments.hindsight.optimum import (
        SCHEDULE_COLUMNS,
        SUMMARY_COLUMNS,
        check,
        hindsight,
    )
    from cell.plumbing.errors import ScenarioError
    from cell.plumbing.output.atomic import OutputDir

    if not (math.isfinite(args.budget) and args.budget > 0.0):
        raise ScenarioError("--budget", "--budget", args.budget, "must be a number of seconds > 0")
    OutputDir.check(args.out, FILES)  # before any work
    scenario = scenario_of(args)
    check(scenario)
    found = hindsight(scenario, args.budget)
    for note in found.notes:
        print(f"cell: note: {note}", file=sys.stderr)
    with OutputDir(args.out, FILES) as out:
        with out.open("schedule.csv", newline="") as f:
            _write(f, SCHEDULE_COLUMNS, found.schedule)
        with out.open("summary.csv", newline="") as f:
            _write(f, SUMMARY_COLUMNS, [tuple(found.summary[c] for c in SUMMARY_COLUMNS)])
    s = found.summary
    how = "exact" if s["exact"] else f"at most {s['parts_upper']} ({s['upper_from']})"
    print(f"{s['scenario']}, seed {s['seed']}: {s['parts_optimum']} of {s['parts']} parts "
          f"after a warm-up of {s['warmup_parts']}; {how}; parts_bound {s['parts_bound']} "
          f"(MILP {s['solve_s']:.2f} s, search {s['search_s']:.2f} s)")
    print(f"wrote {out.target}/{FILES[0]} and {FILES[1]}")
    return 0


def _write(fh: object, columns: tuple[str, ...], rows: list[tuple[object, ...]]) -> None:
    import csv

    from cell.plumbing.csvfile import cell_text

    w = csv.writer(fh, lineterminator="\n")  # type: ignore[arg-type]
    w.writerow(columns)
    for row in rows:
        w.writerow([cell_text(v) for v in row])
