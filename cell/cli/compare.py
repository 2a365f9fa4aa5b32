"""``cell compare A B [--replications N] [--seed S] [--workers N] [--out DIR]``.

Two scenarios (files or built-in names) run side by side with common random
numbers: replication r of both draws the same parts, so their difference is
taken replication by replication (a paired t interval).  Prints, per headline
measure, which is better, by how much, and whether the interval excludes zero;
``--out DIR`` writes the report (as ``cell sweep --report``) and the
replications, as a unit.  Counts (parts delivered, lost, ...) and extremes (closest
spacing, fastest belt, ...) are per run, after the warm-up: if A and B differ in
``run.parts`` or ``run.warmup_parts``, or either has ``run.warmup_parts: auto`` (MSER-5
cuts each run where its own output settles), a warning says so, the verdict leaves them
uncompared and ``differences.csv`` leaves them out (:mod:`cell.experiments.sweep.windows`);
rates still compare.
"""

from __future__ import annotations

import argparse
import math
from typing import TYPE_CHECKING

from cell.cli.common import check_workers, set_argument, workers_argument
from cell.reporting.compare_verdict import PRACTICAL_PER_1000

if TYPE_CHECKING:
    from cell.experiments.sweep import Sweep
    from cell.scenario.schema import Scenario

HELP = "compare two scenarios, paired over common random numbers"
DESCRIPTION = ("Run scenarios A and B with the same replications (common random numbers) and "
               "say, per headline measure, which is better, by how much (paired confidence "
               "interval of A - B) and whether the interval excludes zero.  The verdict, "
               "report.md and the CSVs' scenario column label A and B by each scenario's "
               "name setting (a file without one: its file name); if the two are the same, "
               "by their file names; if those are the same too, as 'A: <name>' and "
               "'B: <name>'.  The overall verdict weighs each difference shown in parts per "
               "1,000: the largest at or above --practical decides; smaller ones are trivial.")
DEFAULT_REPLICATIONS = 100


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("a", metavar="A", help="a scenario file, or a built-in name (baseline)")
    p.add_argument("b", metavar="B", help="the scenario to compare A with")
    p.add_argument("--replications", type=int, default=DEFAULT_REPLICATIONS,
                   help=f"replications of each (default {DEFAULT_REPLICATIONS})")
    p.add_argument("--seed", type=int, default=None,
                   help="root seed of the replications' streams (default: A's run.seed)")
    workers_argument(p)
    p.add_argument("--out", default=None, metavar="DIR",
                   help="write report.md, summary.csv, differences.csv, figures and "
                        "replications.csv into DIR")
    set_argument(p)
    p.add_argument("--policy", default=None, metavar="NAME",
                   help="run this policy on both sides (controller.policy of A and B)")
    p.add_argument("--practical", type=float, default=PRACTICAL_PER_1000, metavar="PER_1000",
                   help="the smallest difference that decides the overall verdict, in parts per "
                        f"1,000 (default {PRACTICAL_PER_1000:g}); a smaller one shown by its "
                        "interval is said, and called trivial")


def _stem(arg: str) -> str:
    """A scenario argument's file name without ``.yaml`` (a built-in's name as given)."""
    from pathlib import Path

    return Path(arg).stem if arg.endswith((".yaml", ".yml")) else Path(arg).name


def labels(a: Scenario, b: Scenario, arg_a: str, arg_b: str) -> tuple[str, str]:
    """What A and B are called (``DESCRIPTION``): their ``name:``, else their file
    names, else ``A: ...`` and ``B: ...``: the first pair that tells them apart."""
    for la, lb in ((a.name, b.name), (_stem(arg_a), _stem(arg_b))):
        if la != lb:
            return la, lb
    return f"A: {a.name}", f"B: {b.name}"


def _warn(sweep: Sweep) -> str | None:
    """Print the comparison's warnings (a nominal cycle off the arrivals, windows apart); the
    windows' one, for the report."""
    import sys

    from cell.experiments.sweep.windows import comparison_window_warning
    from cell.reporting.run_summary import comparison_nominal_warning

    for warning in (comparison_nominal_warning(sweep), comparison_window_warning(sweep)):
        if warning:
            print(f"cell: warning: {warning}", file=sys.stderr)
    return comparison_window_warning(sweep)


def main(args: argparse.Namespace) -> int:
    import tempfile
    from pathlib import Path

    from cell.experiments.sweep import run_sweep, simulate_summary
    from cell.experiments.sweep.spec import MAX_RUNS, comparison
    from cell.plumbing.errors import CellError
    from cell.plumbing.output.paths import check_umask
    from cell.scenario.overrides import parse_sets
    from cell.scenario.schema import load_scenario

    check_umask("cell compare's temporary folder")  # the runs go there, --out or not
    sets = parse_sets(args.sets)
    if args.policy is not None:
        sets["controller.policy"] = args.policy
    a, b = load_scenario(args.a, sets), load_scenario(args.b, sets)
    if args.replications < 2:
        raise CellError(f"--replications {args.replications}: must be at least 2 "
                        "(a confidence interval needs two)")
    if 2 * args.replications > MAX_RUNS:
        raise CellError(f"--replications {args.replications:,}: at most {MAX_RUNS // 2:,} "
                        f"(two scenarios: {MAX_RUNS:,} runs, a sweep's limit)")
    if args.seed is not None and not 0 <= args.seed < 2**63:
        raise CellError(f"--seed {args.seed}: must be a whole number from 0 to 2**63 - 1")
    if not (math.isfinite(args.practical) and args.practical >= 0):
        raise CellError(f"--practical {args.practical}: must be a number of parts per 1,000, "
                        "0 or more")
    check_workers(args.workers)
    seed = a.run.seed if args.seed is None else args.seed
    sweep = comparison(a, b, labels(a, b, args.a, args.b), args.replications, seed)
    target = None
    if args.out:
        from cell.plumbing.output.atomic import OutputDir
        from cell.reporting.experiment.report import REPORT_FILES, Target

        names = (*REPORT_FILES, "replications.csv")
        OutputDir.check(args.out, names)  # before anything runs
        target = Target(Path(args.out), names, False)
    warning = _warn(sweep)
    with tempfile.TemporaryDirectory(prefix="cell-compare-") as work:
        outcome = run_sweep(sweep, work, workers=args.workers, replicate=simulate_summary,
                            warn_windows=False)  # said above, in compare's words
        replications = outcome.replications
    from cell.reporting.compare_judgement import verdict
    from cell.reporting.experiment.report import difference_table, summary_table

    tables = summary_table(replications, sweep), difference_table(replications, sweep)
    print(verdict(*tables, sweep, replications, args.practical))
    if target is not None:
        from cell.reporting.experiment.report import write_report

        write_report(replications, sweep, target, command_line(args, seed), warning, tables)
        print(f"wrote {args.out}/: report.md, summary.csv, differences.csv, figures, "
              "replications.csv")
    return 0


def command_line(args: argparse.Namespace, seed: int) -> str:
    """The command that reproduces this comparison, quoted for a shell: its scenarios,
    replications, seed and every ``--set``."""
    import shlex

    words = ["cell", "compare", args.a, args.b, "--replications", str(args.replications),
             "--seed", str(seed)]
    for value in args.sets or ():
        words += ["--set", value]
    if args.practical != PRACTICAL_PER_1000:
        words += ["--practical", f"{args.practical:g}"]
    return shlex.join(words)
