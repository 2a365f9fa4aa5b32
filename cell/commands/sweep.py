"""``cell sweep SWEEP --out DIR [--workers N] [--scheduler ADDR] [--resume] [--report DIR]``."""

from __future__ import annotations

import argparse
import signal
import threading
from pathlib import Path
from typing import Any

HELP = "replicated sweep over scenario keys (Table 7.1)"
DESCRIPTION = ("Run a grid of scenarios with replications; write replications.csv and, with "
               "--report, Table 7.1.")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("sweep", help="sweep YAML file, or a built-in one by name (table_7_1)")
    p.add_argument("--out", required=True, help="directory for results")
    p.add_argument("--workers", type=int, default=None,
                   help="local worker processes (default: number of cores)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on a dask.distributed cluster at ADDRESS")
    p.add_argument("--resume", action="store_true", help="run only what is missing in --out")
    p.add_argument("--report", default=None, metavar="DIR",
                   help="also write table_7_1.csv and table_7_1.md into DIR")


def _interrupt(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt


def main(args: argparse.Namespace) -> int:
    if threading.current_thread() is not threading.main_thread():
        return _sweep(args)
    # kill (SIGTERM) stops like Ctrl-C: pending tasks cancelled, finished ones kept.
    previous = signal.signal(signal.SIGTERM, _interrupt)
    try:
        return _sweep(args)
    finally:
        signal.signal(signal.SIGTERM, previous)


def _sweep(args: argparse.Namespace) -> int:
    from cell.sweep import load_sweep, run_sweep, simulate_summary

    sweep = load_sweep(args.sweep)
    if args.report:
        from cell.reporting.table_7_1 import check_table_7_1

        check_table_7_1(sweep)
    outcome = run_sweep(sweep, args.out, workers=args.workers, scheduler=args.scheduler,
                        resume=args.resume, replicate=simulate_summary)
    print(f"wrote {Path(args.out) / 'replications.csv'}: {len(sweep.points)} points x "
          f"{sweep.replications} replications ({outcome.tasks_run} tasks run, "
          f"{outcome.tasks_reused} reused)")
    if args.report:
        from cell.reporting.table_7_1 import write_table_7_1

        for path in write_table_7_1(outcome.replications, sweep, args.report):
            print(f"wrote {path}")
    return 0
