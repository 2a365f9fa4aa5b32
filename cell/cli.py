"""The ``cell`` command: ``cell path | run | sweep | figures | mintime | bench``.

Each subcommand is a thin shell in :mod:`cell.commands`: it reads its input,
calls the package, and writes its output whole or not at all.  Any :class:`~cell.errors.CellError` is
reported as one line on stderr with exit code 2.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence
from typing import Any

from cell import __version__
from cell.errors import CellError

#: subcommand -> the module under ``cell.commands`` whose ``main(args)`` runs it.
HANDLERS = {name: f"cell.commands.{name}" for name in
            ("path", "run", "sweep", "figures", "mintime", "bench")}


def _scenario_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("scenario", help="scenario YAML file (see scenarios/)")
    p.add_argument("--set", dest="sets", action="append", metavar="KEY=VALUE",
                   help="override a scenario value, e.g. --set run.parts=100 (repeatable)")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="cell",
        description="Simulate King's (1984) robotic transfer station.")
    parser.add_argument("--version", action="version", version=f"cell {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    p = sub.add_parser("path", help="write the joint-step table of the transfer path (CSV)",
                       description="Solve the transfer path once (thesis §4.2, eq. 6.7) and "
                                   "write one row per path point: coordinates, joint angles, "
                                   "motor steps, move length, load and LO/TD events.")
    _scenario_args(p)
    p.add_argument("--out", required=True, help="CSV file to write")

    p = sub.add_parser("run", help="simulate one scenario; write parts.csv and summary.csv",
                       description="Run the cell in simulated time under the scenario's policy.")
    _scenario_args(p)
    p.add_argument("--out", required=True, help="directory for parts.csv and summary.csv")

    p = sub.add_parser("sweep", help="replicated sweep over scenario keys (Table 7.1)",
                       description="Run a grid of scenarios with replications; write "
                                   "replications.csv and, with --report, Table 7.1.")
    p.add_argument("sweep", help="sweep YAML file (see scenarios/table_7_1.yaml)")
    p.add_argument("--out", required=True, help="directory for results")
    p.add_argument("--workers", type=int, default=None,
                   help="local worker processes (default: number of cores)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on a dask.distributed cluster at ADDRESS")
    p.add_argument("--resume", action="store_true", help="run only what is missing in --out")
    p.add_argument("--report", default=None, metavar="DIR",
                   help="also write table_7_1.csv and table_7_1.md into DIR")

    p = sub.add_parser("figures", help="regenerate the thesis's figures as PNG",
                       description="Write reports/figures/figNN_<slug>.png for Fig. 8-30.")
    p.add_argument("--out", default="reports/figures", help="directory for the PNGs")
    p.add_argument("--scenario", default="scenarios/baseline.yaml", help="scenario to draw")
    p.add_argument("--set", dest="sets", action="append", metavar="KEY=VALUE",
                   help="override a scenario value (repeatable)")

    p = sub.add_parser("mintime", help="minimum-time motion along the path (Shin & McKay)",
                       description="Phase-plane minimum-time parameterisation of R II and "
                                   "R IV; writes FILE.csv and FILE.json.")
    _scenario_args(p)
    p.add_argument("--out", required=True, help="output stem: FILE.csv and FILE.json")

    p = sub.add_parser("bench", help="measure simulation and planner speed",
                       description="Benchmarks; writes a JSON of the figures.")
    p.add_argument("--out", default="reports/bench.json", help="JSON file to write")
    return parser


def _handler(command: str) -> Any:
    """The subcommand's function, imported only when it runs (keeps ``--help`` fast)."""
    return importlib.import_module(HANDLERS[command]).main


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    handler = _handler(args.command)
    try:
        return int(handler(args) or 0)
    except CellError as exc:
        print(f"cell: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("cell: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
