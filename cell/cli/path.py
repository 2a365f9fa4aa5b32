"""``cell path SCENARIO --out steps.csv``: the joint-step table of the transfer path."""

from __future__ import annotations

import argparse

from cell.cli.common import scenario_arguments, scenario_of

HELP = "write the joint-step table of the transfer path (CSV)"
DESCRIPTION = ("Solve the transfer path once (thesis §4.2, eq. 6.7) and write one row per path "
               "point: coordinates, joint angles, motor steps, move length, load and LO/TD events.")


def add_arguments(p: argparse.ArgumentParser) -> None:
    scenario_arguments(p)
    p.add_argument("--out", required=True, help="CSV file to write")


def main(args: argparse.Namespace) -> int:
    from cell.plumbing.output.atomic import check_file, write_csv
    from cell.sim.physics_checks import step_table

    check_file(args.out)  # before any work (refuses '-': no command writes to standard output)
    scenario = scenario_of(args)
    table = step_table(scenario)
    write_csv(table.to_frame(), args.out)
    n = table.path.n_points
    print(f"wrote {args.out}: {n} points, {n - 1} moves; R IV {table.regime_length('R4'):.4f} in")
    return 0
