"""``cell figures [--out DIR] [--scenario SCENARIO] [--set KEY=VALUE]``: the thesis's Fig. 8-30 as PNG.

The PNGs are one set (:class:`~cell.plumbing.output.atomic.OutputDir`): DIR is checked before
anything is drawn, and the new figures replace the old ones together.
"""

from __future__ import annotations

import argparse

from cell.cli.common import scenario_of, set_argument

HELP = "regenerate the thesis's figures as PNG"
DESCRIPTION = "Write figNN_<slug>.png for the thesis's Fig. 8-30 into --out."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default="reports/figures", metavar="DIR",
                   help="directory for the PNGs (default: reports/figures)")
    p.add_argument("--scenario", default="baseline",
                   help="scenario to draw: a file or a built-in name (default: baseline)")
    set_argument(p)


def main(args: argparse.Namespace) -> int:
    import sys

    from cell.plumbing.output.atomic import OutputDir
    from cell.reporting.figures.thesis_figures import NAMES, make_figures
    from cell.reporting.unit_slips import run_warnings
    from cell.sim.assembly import assemble

    def warn(line: str) -> None:
        print(f"cell: warning: {line}", file=sys.stderr)

    names = list(NAMES)
    OutputDir.check(args.out, names)  # before any work
    scenario = scenario_of(args)
    for line in run_warnings(assemble(scenario)):  # as cell run says them
        warn(line)
    with OutputDir(args.out, names) as out:
        drawn = make_figures(scenario, out.stage, warn=warn,
                             progress=lambda p: print(f"drew {p.name}"))
    print(f"wrote {len(drawn)} figures into {out.target}")
    return 0
