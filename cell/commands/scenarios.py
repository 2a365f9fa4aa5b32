"""``cell scenarios``: the built-in scenario and sweep files, one line each."""

from __future__ import annotations

import argparse

HELP = "list the built-in scenarios (usable by name: cell run baseline)"
DESCRIPTION = ("The scenario and sweep files that ship with cell; any command that takes a "
               "scenario takes one of these names, or a path to your own file.")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--path", action="store_true",
                   help="also print where each file is (copy one to start your own)")


def main(args: argparse.Namespace) -> int:
    from cell import catalog

    names = catalog.names()
    width = max(len(n) for n in names)
    for name in names:
        where = f"  ({catalog.path(name)})" if args.path else ""
        print(f"{name:<{width}}  {catalog.describe(name)}{where}")
    return 0
