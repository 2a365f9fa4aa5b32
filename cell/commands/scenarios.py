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
    by_kind = {k: [n for n in names if catalog.kind(catalog.read(n)) == k] for k in catalog.USE}
    for k, members in by_kind.items():
        if not members:
            continue
        print(f"{k} files ({catalog.USE[k].replace(' it ', ' them ')}):")
        for name in members:
            where = f"  ({catalog.path(name)})" if args.path else ""
            print(f"  {name:<{width}}  {catalog.describe(name)}{where}")
    return 0
