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


@pytest.mark.parametrize("text,expected", [
    ("run: {parts: 1e3}\n", "run.parts = 1000.0: must be a whole number; write 1000"),
    ("run: {seed: 7.0}\n", "run.seed = 7.0: must be a whole number; write 7"),
    ("run: {parts: 10.5}\n", "run.parts = 10.5: must be a whole number"),
    ("name: 2026\n", "name = 2026: must be text; quote it: '2026'"),
    ("name: true\n", "name = True: must be text"),
])
def test_a_value_of_the_wrong_type_says_what_to_write(capsys, tmp_path: Path, text, expected):
    """Counts stay strict, as every int setting is (a float is refused, not rounded), but a
    whole float says how to write it; text that YAML read as a number says to quote it."""
    scenario = tmp_path / "s.yaml"
    scenario.write_text(text)
    assert refused(capsys, "run", scenario, "--out", tmp_path / "out") == f"{scenario}: {expected}"


@pytest.mark.parametrize("text,where", [
    ("run:\n\tparts: 10\n", "line 2, column 1"),            # "cannot start any token"
    ("run:\n  parts: 10\n\tseed: 3\n", "line 3, column 1"),  # "violates indentation"
    ("run:\n    \tparts: 10\n", "line 2, column 5"),
])
def test_a_tab_in_the_indentation_is_called_a_tab(capsys, tmp_path: Path, text, where):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(text)
    line = refused(capsys, "run", scenario, "--out", tmp_path / "out")
    assert line.endswith(f": invalid YAML at {where}: a tab: YAML indents with spaces only")


def test_path_refuses_a_dash_for_out_instead_of_writing_a_file_named_dash(capsys, tmp_path,
                                                                         monkeypatch):
    """No command writes its output to stdout, so '-' is refused, not taken as a file name."""
    monkeypatch.chdir(tmp_path)
    line = refused(capsys, "path", "baseline", "--out", "-")
    assert line.startswith("--out -: cell path writes a CSV file, not standard output")
    assert list(tmp_path.iterdir()) == []
