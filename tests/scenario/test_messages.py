"""One clean line for small input mistakes (findings entry 15), each naming what to write."""

from __future__ import annotations

from pathlib import Path

import pytest

from cell.cli.main import main
from tests.prose import in_order


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
    assert line.startswith(f"--set {pair!r}: ") and in_order(line, "KEY=VALUE", "run.parts=100")
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
    assert line.startswith(f"{scenario}: ") and in_order(line, f"YAML at {where}: a tab", "spaces")


@pytest.mark.parametrize("argv, what", [
    (["path", "baseline", "--out", "-"], "a file"),
    (["run", "baseline", "--out", "-"], "a directory"),
    (["compare", "baseline", "non_adaptive", "--out", "-"], "a directory"),
    (["sweep", "table_7_1", "--out", "-"], "a directory"),
    (["fit", "trace.csv", "--out", "-"], "a file"),
    (["fit", "trace.csv", "--out", "f.yaml", "--figure", "-"], None),  # the suffix, first
    (["path", "baseline", "--out", "./-"], None),  # a file named '-', asked for: written
])
def test_a_dash_for_an_output_is_refused_instead_of_writing_a_file_named_dash(
        capsys, tmp_path, monkeypatch, argv, what):
    """No command writes its output to stdout, so '-' is refused, not taken as a file name."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "trace.csv").write_text("interarrival_s\n" + "".join(f"{20 + i % 7}\n" for i in range(40)))
    if "./-" in argv:
        assert main(argv) == 0 and (tmp_path / "-").is_file()
        return
    line = refused(capsys, *argv)
    if what is not None:
        assert line.startswith("--out -: ") and in_order(line, "standard output", f"name {what}")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["trace.csv"]


@pytest.mark.parametrize("command, suffix, what", [
    ("run", ".yaml", "scenario"), ("run", ".yml", "scenario"), ("sweep", ".yaml", "sweep")])
def test_a_name_without_its_suffix_suggests_the_file_beside_it(capsys, tmp_path, monkeypatch,
                                                               command, suffix, what):
    """``cell run slow_robot`` with slow_robot.yaml here: not a built-in name, but that file."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / f"slow_robot{suffix}").write_text("run: {parts: 3}\n")
    line = refused(capsys, command, "slow_robot", "--out", "out")
    assert line.startswith("slow_robot: (file) = 'slow_robot': ")
    assert in_order(line, f"no such {what} file", f"slow_robot{suffix}?")
    assert refused(capsys, command, "slow_robots", "--out", "out").endswith(f"no such {what} file")
