"""The parser of ``cell`` and its subcommands (:mod:`cell.cli.main` runs what it parses)."""

from __future__ import annotations

import argparse
import functools
import importlib
from typing import Any, NoReturn

from cell import __version__

#: Subcommands in the order ``cell --help`` lists them; each is cell.cli.<name>.
COMMANDS = ("run", "sweep", "compare", "optimize", "sensitivity", "fit", "figures", "animate",
            "path", "mintime", "hindsight", "scenarios", "schema", "docs", "bench")


class Parser(argparse.ArgumentParser):
    """argparse with usage errors on one line (``cell: error: run: ... (see cell run --help)``)
    and no exit."""

    def error(self, message: str) -> NoReturn:
        sub = self.prog.partition(" ")[2]  # "cell run" -> "run": named once, not "cell" twice
        raise UsageError(f"{sub + ': ' if sub else ''}{message} (see {self.prog} --help)")


class UsageError(Exception):
    """A usage error, its line as :class:`Parser` wrote it."""


def command_module(name: str) -> Any:
    """The module of subcommand ``name``."""
    return importlib.import_module(f"cell.cli.{name}")


def build_parser() -> argparse.ArgumentParser:
    """The parser of ``cell`` and its subcommands, built once a process: building it (argparse
    and gettext's look-ups for each of the commands' options) took about 3.8 ms, and the test
    suite runs ``main`` in-process some 2,300 times (about 9 s of CPU).  Parsing leaves it
    unchanged: each ``parse_known_args`` gives a new namespace."""
    return _parser()


@functools.cache
def _parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="cell",
        description="Simulate King's (1984) robotic transfer station: what-if studies of an "
                    "adaptive robot cell.")
    parser.add_argument("--version", action="version", version=f"cell {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        module = command_module(name)
        p = sub.add_parser(name, help=module.HELP, description=module.DESCRIPTION)
        module.add_arguments(p)
        SUBPARSERS[name] = p
    return parser


#: Each subcommand's parser, by name, as build_parser made it (once, with the parser): an
#: argument the subcommand does not know is its usage error, pointing to its own --help.
SUBPARSERS: dict[str, argparse.ArgumentParser] = {}
