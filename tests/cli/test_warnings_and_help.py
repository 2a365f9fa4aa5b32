"""What ``cell`` says besides its results: the warnings a command met, as Python's own default
filters would show them (a library's deprecations and compile-time warnings are not the user's),
and ``--workers``' default as each command's help states it, the value the command uses."""

from __future__ import annotations

import argparse
import re
import warnings
from pathlib import Path

import pytest

import cell
import cell.cli.optimize
import cell.cli.scenarios
import cell.cli.sensitivity
import cell.cli.sweep
from cell.cli.main import main

#: A library's source file, as a warning from compiling it names it.
LIBRARY = "/somewhere/site-packages/toppra/algorithm/reachabilitybased/x.py"
OWN = str(Path(cell.__file__).parent / "experiments" / "fit.py")


def emitting(*raised: tuple[type[Warning], str, str]):
    """A command's ``main`` that meets each (category, text, file) warning, then succeeds."""
    def run(args: argparse.Namespace) -> int:
        for category, text, filename in raised:
            warnings.warn_explicit(text, category, filename, 1)
        return 0
    return run


@pytest.mark.parametrize(("category", "filename", "said"), [
    (DeprecationWarning, LIBRARY, False),  # toppra's 'invalid escape sequence' (Python 3.11)
    (SyntaxWarning, LIBRARY, False),  # the same from Python 3.12
    (PendingDeprecationWarning, LIBRARY, False),
    (DeprecationWarning, OWN, True),  # cell's own: its developers must see it
    (UserWarning, LIBRARY, True),  # shown by Python whoever raised it
    (RuntimeWarning, LIBRARY, True),
    (ResourceWarning, OWN, False),
])
def test_a_warning_is_said_as_pythons_default_filters_would(monkeypatch, capsys, category,
                                                            filename, said):
    monkeypatch.setattr(cell.cli.scenarios, "main",
                        emitting((category, "invalid escape sequence '\\s'", filename)))
    assert main(["scenarios"]) == 0
    err = capsys.readouterr().err
    assert ("invalid escape sequence" in err) is said
    assert (category.__name__ in err) is said


def test_four_library_deprecations_and_one_warning_of_ours_say_one_line(monkeypatch, capsys):
    raised = [(DeprecationWarning, f"invalid escape sequence '\\{c}'", LIBRARY) for c in "sdpw"]
    monkeypatch.setattr(cell.cli.scenarios, "main",
                        emitting(*raised, (UserWarning, "a fit left out", OWN)))
    assert main(["scenarios"]) == 0
    lines = [x for x in capsys.readouterr().err.splitlines() if x.startswith("cell: warning")]
    assert len(lines) == 1 and "a fit left out" in lines[0]


def _workers_default(command: str) -> str:
    from cell.cli.parser import SUBPARSERS, build_parser

    build_parser()
    action = next(a for a in SUBPARSERS[command]._actions if "--workers" in a.option_strings)
    found = re.search(r"default: ([^)]+)\)", action.help or "")
    assert found, action.help
    return found[1]


@pytest.mark.parametrize(("command", "module", "uses"), [
    ("optimize", cell.cli.optimize, "args.workers or 1"),
    ("sensitivity", cell.cli.sensitivity, "args.workers or 1"),
])
def test_workers_default_in_help_is_what_the_command_uses(command, module, uses):
    """optimize and sensitivity run one worker when --workers is left out (their code says
    ``args.workers or 1``): their help says 1, not the number of cores."""
    assert uses in Path(module.__file__).read_text()
    assert _workers_default(command) == "1"


def test_a_sweep_takes_a_worker_a_core_by_default():
    from cell.experiments.sweep.runner import check_workers

    assert _workers_default("sweep") == "number of cores"
    assert check_workers(None) == (__import__("os").cpu_count() or 1)
