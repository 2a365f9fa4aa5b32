"""The command line: subcommands, `cell path`, and hostile input."""

import importlib
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cell.cli.main import build_parser, main
from tests.prose import in_order

SUBCOMMANDS = ["path", "run", "sweep", "compare", "figures", "mintime", "bench", "fit",
               "animate", "scenarios", "schema", "docs", "optimize", "sensitivity",
               "hindsight"]


def test_help_lists_the_subcommands(capsys):
    """In-process (``python -m cell`` in a real process: test_installed_cell_command's console
    script, and tests/plumbing, tests/robust)."""
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    for name in SUBCOMMANDS:
        assert name in out


def test_installed_cell_command():
    exe = Path(sys.executable).parent / "cell"
    assert exe.exists(), "the `cell` console script is installed with the package"
    out = subprocess.run([str(exe), "--help"], capture_output=True, text=True, check=True).stdout
    assert all(name in out for name in SUBCOMMANDS)


def test_parser_knows_every_subcommand():
    parser = build_parser()
    for name in SUBCOMMANDS:
        argv = {"path": ["x", "--out", "y"], "run": ["x", "--out", "y"],
                "mintime": ["x", "--out", "y"], "sweep": ["x", "--out", "y"],
                "fit": ["x"], "animate": ["x", "--out", "y.gif"],
                "compare": ["a", "b"], "optimize": ["x", "--out", "y"],
                "sensitivity": ["x", "--out", "y"], "hindsight": ["x", "--out", "y"]}.get(name, [])
        assert parser.parse_args([name, *argv]).command == name


def test_cell_path_writes_the_thesis_table(tmp_path):
    """460 rows, angles in range, R IV 35.54 in and 1125π base steps,
    9.9855 s at the nominal rate and 7.489 s at the maximum."""
    out = tmp_path / "steps.csv"
    assert main(["path", "scenarios/baseline.yaml", "--out", str(out)]) == 0
    df = pd.read_csv(out, keep_default_na=False)
    assert len(df) == 460
    ranges = {1: (-90, 90), 2: (-35, 144), 3: (-149, 0), 4: (-180, 0), 5: (-180, 180)}
    for j, (lo, hi) in ranges.items():
        col = df[f"theta{j}_deg"]
        assert col.between(lo - 1e-9, hi + 1e-9).all(), j
    r4 = df[df.regime == "R4"]
    assert r4.move_in.sum() == pytest.approx(35.54, abs=0.01)
    assert abs(r4.steps1.sum()) == pytest.approx(1125 * np.pi, rel=0.01)
    # base-limited R IV: steps over the base's rate at no load (thesis §6.1 linear model)
    base_max = 0.4194527 * 1125  # steps/s, robot.motors in scenarios/baseline.yaml
    assert (r4.steps1.abs() / (0.75 * base_max)).sum() == pytest.approx(9.9855, rel=0.005)
    assert (r4.steps1.abs() / base_max).sum() == pytest.approx(7.489, rel=0.005)
    assert set(df.event) == {"", "LO", "TD"}


@pytest.mark.parametrize("yaml_text,needle", [
    ("robot:\n  motrs: {}\n", "robot.motrs"),
    ("run:\n  parts: ten\n", "run.parts"),
    ("path:\n  bot_in: [-26.0, 0.0, 3.0]\n", "path.bot_in"),
    ("belts:\n  input_nominal_in_s: -1\n", "belts.input_nominal_in_s"),
])
def test_hostile_scenario_one_line_exit_2_no_file(tmp_path, capsys, yaml_text, needle):
    """In-process: the refusal is the command's (a real process's exit 2 and one line:
    tests/plumbing/test_output_streams.py, tests/hostile/test_hostile_commands.py)."""
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml_text)
    out = tmp_path / "out" / "steps.csv"
    assert main(["path", str(bad), "--out", str(out)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and str(bad) in lines[0] and needle in lines[0]
    assert not out.exists()
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_set_overrides_from_the_command_line(tmp_path):
    out = tmp_path / "steps.csv"
    assert main(["path", "scenarios/baseline.yaml", "--set", "path.moves.R4=100",
                 "--out", str(out)]) == 0
    assert len(pd.read_csv(out)) == 410
    assert main(["path", "scenarios/baseline.yaml", "--set", "nonsense", "--out", str(out)]) == 2


def test_every_subcommand_has_its_module():
    from cell.cli.parser import COMMANDS

    assert set(COMMANDS) == set(SUBCOMMANDS)
    for name in SUBCOMMANDS:
        module = importlib.import_module(f"cell.cli.{name}")
        assert callable(module.main) and callable(module.add_arguments), name


def test_built_in_scenarios_are_listed_and_run_by_name(tmp_path, capsys):
    assert main(["scenarios"]) == 0
    listed = capsys.readouterr().out
    assert "baseline" in listed and "table_7_1" in listed
    out = tmp_path / "run"
    assert main(["run", "baseline", "--set", "run.parts=5", "--out", str(out)]) == 0
    assert (out / "parts.csv").is_file()


def test_built_in_files_are_listed_by_what_they_are_for(capsys):
    from cell.scenario import catalog

    assert main(["scenarios"]) == 0
    listed = capsys.readouterr().out
    headings = [line for line in listed.splitlines() if not line.startswith(" ")]
    assert [h.split()[0] for h in headings] == ["scenario", "sweep", "dynamics", "study"]
    section = {h.split()[0]: [] for h in headings}
    current = None
    for line in listed.splitlines():
        if line.startswith(" "):
            section[current].append(line.split()[0])
        else:
            current = line.split()[0]
    assert set(sum(section.values(), [])) == set(catalog.names())
    assert "table_7_1" in section["sweep"] and "microbot_dynamics" in section["dynamics"]
    # every file listed as a kind loads as that kind
    from cell.experiments.sweep.spec import load_sweep
    from cell.scenario.dynamics_file import load_dynamics
    from cell.scenario.schema import load_scenario

    for name in section["scenario"]:
        load_scenario(name)
    for name in section["sweep"]:
        load_sweep(name)
    for name in section["dynamics"]:
        load_dynamics(catalog.path(name))
    from cell.experiments.study import load_study

    for name in section["study"]:
        load_study(catalog.path(name))


@pytest.mark.parametrize("command,name,found", [
    (["run"], "table_7_1", "sweep"), (["run"], "microbot_dynamics", "dynamics"),
    (["sweep"], "baseline", "scenario"), (["sweep"], "microbot_dynamics", "dynamics"),
    (["compare", "baseline"], "whatif", "sweep")])
def test_a_file_of_the_wrong_kind_is_named_for_what_it_is(tmp_path, capsys, command, name, found):
    code = main([*command, name, "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code != 0 and len(err) == 1
    assert f"{name}.yaml" in err[0] and f"this is a {found} file" in err[0]
    assert not (tmp_path / "out").exists()


def test_schema_describes_every_section(capsys):
    import json

    assert main(["schema"]) == 0
    schema = json.loads(capsys.readouterr().out)
    assert {"cell", "path", "part", "robot", "belts", "arrivals", "controller", "run",
            "mintime"} <= set(schema["properties"])



def test_schema_help_is_plain_text_and_its_file_comes_with_the_line_that_uses_it(tmp_path, capsys):
    """``cell schema --help`` reads without the docstring's markup; ``--out`` names the first line
    that the YAML language server reads, as docs/usage.md's "Editors" gives it."""
    with pytest.raises(SystemExit):
        build_parser().parse_args(["schema", "--help"])
    assert "``" not in capsys.readouterr().out
    out = tmp_path / "scenario.schema.json"
    assert main(["schema", "--out", str(out)]) == 0
    assert "# yaml-language-server: $schema=scenario.schema.json" in capsys.readouterr().out.splitlines()
    root = Path(__file__).resolve().parents[2]
    usage = (root / "docs" / "usage.md").read_text(encoding="utf-8")   # the README points there
    assert "`# yaml-language-server: $schema=scenario.schema.json`" in usage

def test_a_built_in_file_is_named_in_reports_as_a_user_would_type_it(tmp_path):
    from cell.scenario import catalog

    assert catalog.shown(catalog.resolve("whatif")) == "whatif"
    assert catalog.shown("scenarios/whatif.yaml") == "scenarios/whatif.yaml"
    own = tmp_path / "whatif.yaml"
    assert catalog.shown(own) == str(own)


def test_only_a_plain_name_falls_back_to_a_built_in_scenario(tmp_path, monkeypatch, capsys):
    """``baseline`` is the built-in scenario from any folder; a path with a folder in it
    that is not there is a missing file, named as typed, not the built-in of that name."""
    from cell.scenario import catalog

    monkeypatch.chdir(tmp_path)
    assert catalog.resolve("baseline") == catalog.path("baseline")
    for typed in ("../scenarios/baseline", "./baseline", "sub/baseline.yaml"):
        assert catalog.resolve(typed) == Path(typed)
        assert main(["run", typed, "--out", "o"]) == 2
        shown = Path(typed)  # as pathlib writes it: ./baseline is baseline
        assert f"{shown}: (file) = '{shown}': no such scenario file" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_cell_run_says_when_a_short_trace_is_replayed(tmp_path, capsys):
    """A trace shorter than the run's T_1 .. T_{n+1} is replayed from its start, and
    ``cell run`` says so, by how many times; a long enough trace is not mentioned."""
    (tmp_path / "gaps.csv").write_text("interarrival_s\n" + "\n".join(["21.0", "24.5"] * 5))
    scenario = tmp_path / "traced.yaml"
    scenario.write_text("arrivals: {trace_csv: gaps.csv}\nrun: {parts: 25}\n")
    assert main(["run", str(scenario), "--out", str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("cell run: traced (adaptive), 25 parts")
    assert in_order(out, "gaps.csv holds 10 inter-arrival", f"needs {25 + 1}")  # T_1 .. T_26
    parts = pd.read_csv(tmp_path / "a" / "parts.csv")
    assert parts["interarrival_s"].tolist() == [21.0, 24.5] * 12 + [21.0]
    assert main(["run", str(scenario), "--set", "run.parts=9", "--out", str(tmp_path / "b")]) == 0
    assert "replayed" not in capsys.readouterr().out
    # one time a part: only the last part's look-ahead (T_{n+1}) comes round, and it says so
    assert main(["run", str(scenario), "--set", "run.parts=10", "--out", str(tmp_path / "c")]) == 0
    out = capsys.readouterr().out
    assert "replayed" not in out and "the last part's next arrival" in out
    assert pd.read_csv(tmp_path / "c" / "parts.csv")["interarrival_s"].tolist() == [21.0, 24.5] * 5


def test_an_hours_long_run_says_when_its_trace_is_replayed(tmp_path, capsys):
    """With run.hours the trace is replayed if its times end before the run does (227.5 s
    here); the run.parts default (500) has nothing to do with it."""
    (tmp_path / "gaps.csv").write_text("interarrival_s\n" + "\n".join(["21.0", "24.5"] * 5))
    (tmp_path / "traced.yaml").write_text("arrivals: {trace_csv: gaps.csv}\nrun: {hours: 0.1}\n")
    assert main(["run", str(tmp_path / "traced.yaml"), "--out", str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out
    assert out.startswith("cell run: traced (adaptive), 0.1 hours")
    covers = 5 * (21.0 + 24.5) / 3600  # the trace's hours
    assert in_order(out, f"gaps.csv covers {covers:.3g}", "0.1 hours", "replayed")
    gaps = pd.read_csv(tmp_path / "a" / "parts.csv")["interarrival_s"].tolist()
    assert len(gaps) > 10 and gaps == ([21.0, 24.5] * 10)[:len(gaps)]  # the trace, round again
    assert main(["run", str(tmp_path / "traced.yaml"), "--set", "run.hours=0.05",
                 "--out", str(tmp_path / "b")]) == 0
    assert "replayed" not in capsys.readouterr().out and "holds" not in out


def test_cell_docs_reads_the_pages_its_output_refers_to(tmp_path, capsys):
    """``cell docs`` lists every page of docs/; a page by name (or as the output writes it,
    docs/accounting.md) is that file's text; an unknown page is one line, exit 2."""
    docs = Path(__file__).resolve().parents[2] / "docs"
    assert main(["docs"]) == 0
    listed = capsys.readouterr().out
    for page in docs.glob("*.md"):
        assert page.stem in listed
    for name in ("accounting", "docs/accounting.md", "Accounting.MD"):
        assert main(["docs", name]) == 0
        assert capsys.readouterr().out == (docs / "accounting.md").read_text(encoding="utf-8")
    assert main(["docs", "nope"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'nope'" in err[0] and "accounting" in err[0]


def test_an_hours_long_run_shows_its_progress_towards_the_parts_expected(
        tmp_path, monkeypatch, capsys):
    """``run.hours`` gives no part count: the progress counts towards the parts expected
    (hours over the mean inter-arrival time) and ends at the parts that came."""
    from cell.cli import run as run_command

    monkeypatch.setattr(run_command, "PROGRESS_FROM_PARTS", 50)
    assert main(["run", "baseline", "--set", "run.hours=2", "--out", str(tmp_path / "o")]) == 0
    arrived = int(pd.read_csv(tmp_path / "o" / "summary.csv")["parts_arrived"][0])
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("cell run: ")]
    assert lines, "a log gets progress lines"
    assert lines[-1].startswith(f"cell run: {arrived:,}/{arrived:,} parts (100 %), done in ")
    first_total = int(lines[0].split("/")[1].split()[0].replace(",", ""))
    assert abs(first_total - arrived) < 0.25 * arrived  # 2 h over the mean gap, about


def test_a_warning_is_one_line_but_not_an_unclosed_file_freed_meanwhile(monkeypatch, capsys):
    """A command's warnings come as ``cell: warning:`` lines; a ResourceWarning does not (an
    object of anybody's, freed while the command ran, as Python's own filters hide it)."""
    import warnings

    import cell.cli.scenarios as command

    real, said = command.main, "a sample warning"

    def warns(args):
        warnings.warn("unclosed file <_io.TextIOWrapper name=21>", ResourceWarning, stacklevel=1)
        warnings.warn(said, UserWarning, stacklevel=1)
        return real(args)

    monkeypatch.setattr(command, "main", warns)
    assert main(["scenarios"]) == 0
    lines = [line for line in capsys.readouterr().err.splitlines() if line.startswith("cell: warning")]
    assert lines == [f"cell: warning: {said} (UserWarning)"]
