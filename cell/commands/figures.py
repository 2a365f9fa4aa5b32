"""``cell figures [--out DIR] [--scenario FILE]``: the thesis's Fig. 8-30 as PNG."""

from __future__ import annotations

import argparse

from cell.commands import set_argument

HELP = "regenerate the thesis's figures as PNG"
DESCRIPTION = "Write figNN_<slug>.png for the thesis's Fig. 8-30 into --out."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default="reports/figures", help="directory for the PNGs")
    p.add_argument("--scenario", default="baseline",
                   help="scenario to draw: a file or a built-in name (default: baseline)")
    set_argument(p)


def main(args: argparse.Namespace) -> int:
    from cell.errors import CellError
    from cell.figures import make_figures
    from cell.overrides import parse_sets
    from cell.scenario import load_scenario

    scenario = load_scenario(args.scenario, parse_sets(getattr(args, "sets", None)))
    try:
        make_figures(scenario, args.out, progress=lambda p: print(f"wrote {p}"))
    except OSError as exc:
        raise CellError(f"cannot write figures into {args.out}: {exc.strerror or exc}") from None
    return 0
