"""``cell figures [--out DIR] [--scenario FILE]``: the thesis's Fig. 8-30 as PNG."""

from __future__ import annotations

import argparse

from cell.errors import CellError
from cell.figures import make_figures
from cell.overrides import parse_sets
from cell.scenario import load_scenario


def main(args: argparse.Namespace) -> int:
    scenario = load_scenario(args.scenario, parse_sets(getattr(args, "sets", None)))
    try:
        make_figures(scenario, args.out, progress=lambda p: print(f"wrote {p}"))
    except OSError as exc:
        raise CellError(f"cannot write figures into {args.out}: {exc.strerror or exc}") from None
    return 0
