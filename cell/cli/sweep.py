"""``cell sweep SWEEP --out DIR [--workers N] [--scheduler ADDR] [--resume] [--report DIR]``."""

from __future__ import annotations

import argparse
import os
import shlex
import signal
import sys
import threading
from pathlib import Path
from typing import Any

from cell.cli.common import check_workers, set_argument, workers_argument
from cell.plumbing.interrupts import exit_now, stopped_by
from cell.plumbing.startup import kept_ignored

HELP = "replicated sweep over scenario keys, with its report"
DESCRIPTION = ("Run a grid of scenarios with replications (common random numbers); write "
               "replications.csv and, with --report, the experiment's report: summary.csv, "
               "differences.csv (paired), report.md and a figure per headline measure "
               "(and Table 7.1 beside the thesis for a sweep laid out like it).")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("sweep", help="sweep YAML file, or a built-in one by name (table_7_1)")
    p.add_argument("--out", required=True, help="directory for results")
    workers_argument(p)
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on a dask.distributed cluster at ADDRESS")
    p.add_argument("--resume", action="store_true", help="run only what is missing in --out")
    p.add_argument("--report", default=None, metavar="DIR",
                   help="also write the report into DIR, as a unit (into DIR/NAME/ if DIR "
                        "holds other files)")
    p.add_argument("--select-best", default=None, metavar="MEASURE",
                   help="then choose the best point on MEASURE by Kim & Nelson's KN, running more "
                        "replications where needed; writes selection.csv into --out")
    p.add_argument("--delta", type=float, default=None,
                   help="with --select-best: the indifference zone, in MEASURE's units (required)")
    p.add_argument("--pcs", type=float, default=0.95,
                   help="with --select-best: the probability of correct selection (default 0.95)")
    p.add_argument("--goal", choices=("maximize", "minimize"), default=None,
                   help="with --select-best: whether more is better (default: by the measure)")
    set_argument(p)  # on top of the sweep file's set: (a key the grid varies is refused)
    p.add_argument("--format", choices=("csv", "parquet"), default="csv",
                   help="the result file: replications.csv (default) or, with parquet, "
                        "replications.parquet in its place (the same table)")


class _Stop:
    """The handler of Ctrl-C (SIGINT) and kill (SIGTERM) during ``cell sweep``: the first
    stops the sweep (KeyboardInterrupt: pending tasks cancelled, workers killed, finished
    tasks kept); the ones after it are ignored, so nothing cuts the stopping short
    (``timeout`` sends its signal twice, a terminal's Ctrl-C reaches the workers too)."""

    #: The signals handled: those the local workers ignore (cell.experiments.sweep.runner.STOP_SIGNALS).
    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self) -> None:
        self.signum: int | None = None

    def __call__(self, signum: int, frame: Any) -> None:
        self.signum = signum
        for number in self.SIGNALS:
            signal.signal(number, signal.SIG_IGN)
        raise KeyboardInterrupt

    @property
    def code(self) -> int:
        """The exit code: 128 + the signal, 130 for Ctrl-C and 143 for kill, as a shell
        reports ``cell run`` stopped by either."""
        return 128 + (self.signum or signal.SIGINT)


def main(args: argparse.Namespace) -> int:
    if threading.current_thread() is not threading.main_thread():
        return _sweep(args, _Stop())
    stop = _Stop()
    previous = {number: signal.signal(number, stop) for number in stop.SIGNALS
                if not kept_ignored(number)}
    try:
        code = _sweep(args, stop)
    except BaseException:
        if stop.signum is None:
            raise
        print(stopped_by(None, stop.signum)[1], file=sys.stderr)  # loading, or writing the report
        code = stop.code
    finally:
        if stop.signum is None:
            for number, handler in previous.items():
                signal.signal(number, signal.SIG_DFL if handler is None else handler)
    if stop.signum is not None:
        exit_now(code)
    return code


def _sweep(args: argparse.Namespace, stop: _Stop) -> int:
    from cell.experiments.sweep import load_sweep, run_sweep, simulate_summary
    from cell.experiments.sweep.checks import size_note
    from cell.experiments.sweep.outdir import check_out, check_owner, lock
    from cell.plumbing.output.paths import check_umask
    from cell.reporting.experiment.text import first_tables
    from cell.scenario.overrides import parse_sets

    check_umask(args.out)  # its folders could not be written in
    out = check_out(args.out)  # before the sweep file's points are built and checked
    _check_select(args)
    check_workers(args.workers, args.scheduler)
    sweep = load_sweep(args.sweep, parse_sets(args.sets))
    _check_select(args, sweep)  # what the sweep file decides: before anything runs or is written
    check_owner(sweep, out, args.resume)  # no results of another sweep, nor this one's, lost
    target = None
    if args.report:
        from cell.reporting.experiment.report import plan_report

        target = plan_report(sweep, args.report, results=args.out)  # before anything runs
    from cell.reporting.run_summary import nominal_warning

    if warning := nominal_warning(sweep):  # run_sweep adds the overload warning
        print(f"cell: warning: {warning}", file=sys.stderr)
    if note := size_note(sweep, None if args.scheduler else args.workers or os.cpu_count()):
        print(f"cell sweep: {note}", file=sys.stderr)
    try:
        with lock(out):  # a second sweep into the same --out is refused
            outcome = run_sweep(sweep, out, workers=args.workers, scheduler=args.scheduler,
                                resume=args.resume, replicate=simulate_summary,
                                result_format=args.format)
    except BaseException as exc:  # stopped: by Ctrl-C or kill, whatever it broke on the way
        if stop.signum is None and not isinstance(exc, KeyboardInterrupt):
            raise
        from cell.experiments.sweep.outdir import finished_tasks

        kept = len(finished_tasks(args.out))
        print(f"cell sweep: stopped; {kept} finished task{'s' if kept != 1 else ''} kept in "
              f"{args.out}: the same command with --resume runs only the rest", file=sys.stderr)
        return stop.code
    counts = sorted(set(outcome.counts.values()))
    reps = (f"{counts[0]}" if len(counts) == 1 else f"{counts[0]}-{counts[-1]}")
    print(f"wrote {outcome.path}: {len(sweep.points)} points x "
          f"{reps} replications ({outcome.tasks_run} tasks run, "
          f"{outcome.tasks_reused} reused)")
    if target is not None:
        from cell.reporting.experiment.report import write_report
        from cell.scenario import catalog

        command = f"cell sweep {shlex.quote(catalog.shown(sweep.source))} --report ..."
        written = list(write_report(outcome.replications, sweep, target, command))
        folders = sorted({str(Path(p).parent) for p in written})
        print(f"wrote {', '.join(folders)}: " + ", ".join(Path(p).name for p in written))
        shown = next((Path(p) for p in written if Path(p).name == "table_7_1.md"), None) or \
            next((Path(p) for p in written if Path(p).name == "report.md"), None)
        if shown is not None:
            print(f"\n{first_tables(shown.read_text(encoding='utf-8'))}\n(all of it: {shown})")
    if args.select_best:
        _select_best(args, sweep, outcome, out)
    return 0


def _check_select(args: argparse.Namespace, sweep: Any = None) -> None:
    """Refuse a --select-best without its --delta (a finite number above 0), or a --pcs out
    of range, before any work; with the ``sweep`` loaded, what KN cannot do on it
    (:func:`cell.experiments.selection.check_sweep`)."""
    import math

    from cell.experiments.selection import check_sweep
    from cell.experiments.study import summary_measures
    from cell.plumbing.errors import CellError

    if args.select_best is None:
        return
    if sweep is not None:
        check_sweep(sweep, args.select_best, args.goal)
        return
    if args.select_best not in summary_measures():
        raise CellError(f"--select-best {args.select_best}: no run reports it (a measure of the "
                        "run summary: parts_missed, parts_per_hr_wallclock, ...)")
    if args.delta is None or not 0 < args.delta < math.inf:
        raise CellError(f"--delta {args.delta}: --select-best needs the indifference zone, a "
                        "finite number above 0 in the measure's units")
    if not 0.5 < args.pcs < 1:
        raise CellError(f"--pcs {args.pcs}: a probability between 0.5 and 1")


def _select_best(args: argparse.Namespace, sweep: Any, outcome: Any, out: Path) -> None:
    """``--select-best``: KN over the sweep's points, continued on the sweep's own streams."""
    import pandas as pd

    from cell.experiments.selection import select_sweep, sentence, table, verdicts
    from cell.plumbing.output.atomic import write_csv

    sel, labels = select_sweep(sweep, outcome.replications, args.select_best, args.delta,
                               args.pcs, args.goal)
    write_csv(pd.DataFrame({"point": labels, "mean": sel.means, "replications": sel.counts,
                            "verdict": verdicts(sel)}), out / "selection.csv")
    print("\n" + sentence(sel, labels, args.select_best) + "\n")
    print("\n".join(table(sel, labels, args.select_best)))
    print(f"wrote {out / 'selection.csv'}")
