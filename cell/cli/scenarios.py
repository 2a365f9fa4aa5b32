"""``cell scenarios``: the built-in scenario and sweep files, one line each."""

from __future__ import annotations

import argparse
from typing import Any

HELP = "list the built-in scenarios (usable by name: cell run baseline)"
DESCRIPTION = ("The scenario and sweep files that ship with cell; any command that takes a "
               "scenario takes one of these names, or a path to your own file.")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--path", action="store_true",
                   help="also print where each file is (copy one to start your own)")


def describe(name: str, doc: dict[Any, Any]) -> str:
    """A built-in file's ``description``, or its first comment line."""
    from cell.scenario import catalog

    if doc.get("description"):
        return str(doc["description"])
    text = catalog.path(name).read_text(encoding="utf-8")
    first = next((line for line in text.splitlines() if line.startswith("#")), "# ")
    return first.lstrip("# ").strip()


def main(args: argparse.Namespace) -> int:
    from cell.scenario import catalog
    from cell.scenario.yamlio import load_mapping

    names = catalog.names()
    docs = {n: load_mapping(catalog.path(n), "built-in") for n in names}
    width = max(len(n) for n in names)
    by_kind = {k: [n for n in names if catalog.kind(docs[n]) == k] for k in catalog.USE}
    for k, members in by_kind.items():
        if not members:
            continue
        print(f"{k} files ({catalog.USE[k].replace(' it ', ' them ')}):")
        for name in members:
            where = f"  ({catalog.path(name)})" if args.path else ""
            print(f"  {name:<{width}}  {describe(name, docs[name])}{where}")
    return 0
