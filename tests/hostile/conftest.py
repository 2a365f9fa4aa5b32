"""The hostile-input suite: its case count is printed after pytest's summary line."""

from __future__ import annotations

import pytest

from .harness import COUNT


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter) -> None:
    if COUNT["in-process"] or COUNT["subprocess"]:
        terminalreporter.write_line(
            f"hostile inputs: {COUNT['in-process'] + COUNT['subprocess']} cases "
            f"({COUNT['in-process']} in-process, {COUNT['subprocess']} in subprocesses): "
            f"{COUNT['refused']} refused in one line, {COUNT['ran']} ran sanely, "
            f"{COUNT['other']} checked otherwise (kill steps, --help)")


@pytest.fixture(autouse=True)
def _no_fsync(monkeypatch: pytest.MonkeyPatch) -> None:
    """Durability is not under test here (tests/test_output.py kills writers): skip the disk flushes."""
    monkeypatch.setattr("os.fsync", lambda fd: None)
