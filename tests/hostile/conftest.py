"""The hostile-input suite (its counts are printed by tests/conftest.py, summed over workers)."""

from __future__ import annotations

import pytest


@pytest.fixture(autouse=True)
def _no_fsync(monkeypatch: pytest.MonkeyPatch) -> None:
    """Durability is not under test here (tests/plumbing/test_output.py kills writers): skip the
    disk flushes."""
    monkeypatch.setattr("os.fsync", lambda fd: None)
