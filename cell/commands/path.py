"""``cell path SCENARIO --out steps.csv``: the joint-step table of the transfer path."""

from __future__ import annotations

import argparse

from cell.assembly import step_table
from cell.output import write_csv
from cell.overrides import parse_sets
from cell.scenario import load_scenario


def main(args: argparse.Namespace) -> int:
    scenario = load_scenario(args.scenario, parse_sets(args.sets))
    table = step_table(scenario)
    write_csv(table.to_frame(), args.out)
    n = table.path.n_points
    print(f"wrote {args.out}: {n} points, {n - 1} moves; R IV {table.regime_length('R4'):.4f} in")
    return 0
