"""The ``cell`` command: ``cell run | sweep | figures | animate | fit | ... ``.

Each subcommand is a module of :mod:`cell.commands` (its arguments and its
``main``).  This is the one place where failures become what the user sees:
any anticipated failure (:class:`~cell.errors.CellError`: bad input, an output
that cannot be written) is one line on stderr and exit code 2; Ctrl-C is exit
130; a closed pipe (``cell run ... | head``) ends quietly.  Anything else is a
bug and keeps its traceback.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from collections.abc import Sequence
from typing import Any

from cell import __version__
from cell.errors import CellError

#: Subcommands in the order ``cell --help`` lists them; each is cell.commands.<name>.
COMMANDS = ("run", "sweep", "compare", "fit", "figures", "animate", "path", "mintime",
            "scenarios", "schema", "bench")


def _module(name: str) -> Any:
    return importlib.import_module(f"cell.commands.{name}")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="cell",
        description="Simulate King's (1984) robotic transfer station: what-if studies of an "
                    "adaptive robot cell.")
    parser.add_argument("--version", action="version", version=f"cell {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        module = _module(name)
        p = sub.add_parser(name, help=module.HELP, description=module.DESCRIPTION)
        module.add_arguments(p)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(_module(args.command).main(args) or 0)
    except CellError as exc:
        print(f"cell: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("cell: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader went away (cell run ... | head): stop quietly, as Unix tools do
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
