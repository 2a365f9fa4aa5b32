"""One clean line for small input mistakes (findings entry 15), each naming what to write."""

from __future__ import annotations

from pathlib import Path

import pytest

from cell.cli import main


def refused(capsys: pytest.CaptureFixture[str], *argv: object) -> str:
    """The one error line of a refused command (exit 2)."""
    assert main([str(a) for a in argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("cell: error: "), err
    return err.removeprefix("cell: error: ")


@pytest.mark.parametrize("pair", ["run.parts", "=5", ""])
def test_a_set_without_key_and_value_names_the_option_once(capsys, tmp_path: Path, pair):
    out = tmp_path / "out"
    line = refused(capsys, "run", "baseline", "--set", pair, "--out", out)
    assert line == f"--set {pair!r}: expected KEY=VALUE, e.g. run.parts=100"
    assert not out.exists()
