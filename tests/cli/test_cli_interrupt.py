"""Ctrl-C wherever it lands is ``cell: interrupted`` and exit 130: also when it cut an import
short and came back as an ImportError ("initialization failed"), or landed before a command
started.  The unit under test is the classification; two real processes check the exit."""

from __future__ import annotations

import subprocess
import sys

import pytest

import cell.cli.main
from cell.cli.main import INTERRUPTED, interrupted, main


def _raised_while_interrupted(chain: str) -> BaseException:
    """An ImportError raised while a KeyboardInterrupt was handled, linked by ``chain``."""
    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as stop:
            if chain == "cause":
                raise ImportError("initialization failed") from stop
            if chain == "suppressed":
                raise ImportError("initialization failed") from None
            if chain == "deeper":
                try:
                    raise ImportError("initialization failed")
                except ImportError:
                    raise RuntimeError("during the import") from None
            raise ImportError("initialization failed")  # noqa: B904 - the implicit context is the case
    except Exception as exc:
        return exc


@pytest.mark.parametrize("chain", ["context", "cause", "suppressed", "deeper"])
def test_an_error_raised_while_ctrl_c_was_handled_counts_as_the_interrupt(chain):
    assert interrupted(_raised_while_interrupted(chain))


def test_other_errors_are_not_an_interrupt():
    assert interrupted(KeyboardInterrupt())
    assert not interrupted(ImportError("No module named 'x'"))
    a, b = ValueError("a"), ValueError("b")
    a.__context__, b.__context__ = b, a  # a cycle: still an answer
    assert not interrupted(a)


@pytest.mark.parametrize("where", ["command", "parser"])
@pytest.mark.parametrize("error", ["KeyboardInterrupt", "ImportError"])
def test_main_reports_it_in_one_line_and_130(monkeypatch, capsys, where, error):
    def stop(*args, **kwargs):
        if error == "KeyboardInterrupt":
            raise KeyboardInterrupt
        raise _raised_while_interrupted("context")

    target = "cell.cli.scenarios.main" if where == "command" else "cell.cli.main.build_parser"
    monkeypatch.setattr(target, stop)
    assert main(["scenarios"]) == INTERRUPTED
    assert capsys.readouterr().err == "cell: interrupted\n"


def test_an_import_error_of_its_own_keeps_its_traceback(monkeypatch):
    monkeypatch.setattr("cell.cli.scenarios.main", lambda args: __import__("no_such_module_x"))
    with pytest.raises(ImportError):
        main(["scenarios"])


_CHILD = """
import sys
import cell.cli.scenarios as command
def stopped(args):
    try:
        exec("raise KeyboardInterrupt")  # Ctrl-C inside code being exec'd, as in an import
    except KeyboardInterrupt:
        raise ImportError("initialization failed")
command.main = stopped
from cell.cli.main import main
sys.argv = ["cell", "scenarios"]
sys.exit(main())
"""


def test_a_real_process_exits_130_with_one_line():
    """The process's own command line (argv None): ended at once, with 130, no traceback."""
    proc = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True,
                          timeout=120)
    assert (proc.returncode, proc.stderr) == (130, "cell: interrupted\n")


def test_the_process_ends_now_only_when_it_is_the_commands(monkeypatch):
    ended = []
    monkeypatch.setattr(cell.cli.main, "exit_now", ended.append)
    monkeypatch.setattr("cell.cli.scenarios.main", lambda args: exec("raise KeyboardInterrupt"))
    assert main(["scenarios"]) == INTERRUPTED and ended == []
    monkeypatch.setattr(sys, "argv", ["cell", "scenarios"])
    assert main() == INTERRUPTED and ended == [INTERRUPTED]
