"""What the ``cell`` command's subcommands share: the scenario, ``--set`` and ``--workers``
arguments, and reading the scenario they name.

The subcommands are the modules ``cell/cli/<command>.py``, each named after its command
(:data:`cell.cli.parser.COMMANDS`).  Each holds ``HELP``
and ``DESCRIPTION``, ``add_arguments(parser)`` and
``main(args)``; it imports the package inside ``main`` only, so building the
parser (and ``cell --help``) loads nothing heavy, and a command loads only what
it needs.  Nothing below this layer imports it.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from cell.scenario.schema import Scenario


def scenario_arguments(p: argparse.ArgumentParser) -> None:
    """SCENARIO and ``--set KEY=VALUE``, as every scenario command takes them."""
    p.add_argument("scenario", help="a scenario file, or the name of a built-in one "
                                    "(`cell scenarios` lists them), e.g. baseline")
    set_argument(p)


def scenario_of(args: argparse.Namespace) -> Scenario:
    """The scenario of SCENARIO (``args.scenario``) with its ``--set`` overrides."""
    from cell.scenario.overrides import parse_sets
    from cell.scenario.schema import load_scenario

    return load_scenario(args.scenario, parse_sets(args.sets))


def set_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument("--set", dest="sets", action="append", metavar="KEY=VALUE",
                   help="override a scenario value, e.g. --set run.parts=100 or "
                        "--set arrivals.params.scale=6.0 (repeatable)")


def workers_argument(p: argparse.ArgumentParser, default: str = "number of cores") -> None:
    """``--workers N``, as the commands that run a sweep take it; ``default`` says what
    leaving it out means for this command (a sweep takes one worker a core; ``cell optimize``
    and ``cell sensitivity`` one worker)."""
    p.add_argument("--workers", type=int, default=None,
                   help=f"local worker processes (default: {default})")


def check_workers(workers: int | None, scheduler: str | None = None) -> None:
    """Refuse a ``--workers`` the sweep would refuse, before any work
    (:func:`cell.experiments.sweep.runner.check_workers`)."""
    from cell.experiments.sweep.runner import check_workers as check

    check(workers, scheduler)
