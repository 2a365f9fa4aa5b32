"""``--select-best`` and a study's ``select:`` refuse, in one line with exit 2, what KN cannot
do: before the sweep runs where the sweep file already says so (nothing written), and
without writing ``selection.csv`` where only the runs can tell."""

from __future__ import annotations

from pathlib import Path

import pytest

from cell.cli.main import main

BASE = Path(__file__).resolve().parents[2] / "scenarios" / "baseline.yaml"


def _sweep(tmp_path: Path, policies: str = "[non-adaptive]", replications: int = 2,
           cycles: str = "[20.1, 22.5872]", parts: int = 20,
           key: str = "controller.ideal_cycle_s") -> Path:
    path = tmp_path / "s.yaml"
    path.write_text(f"base: {BASE}\nset: {{run.parts: {parts}}}\npolicies: {policies}\n"
                    f"grid: {{{key}: {cycles}}}\n"
                    f"replications: {replications}\nseed: 2\n")
    return path


def _line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


BEFORE = {  # case: (sweep file settings, options, what the line names)
    "infinite delta": ({}, ["--select-best", "parts_missed", "--delta", "inf"], ["--delta", "inf"]),
    "nan delta": ({}, ["--select-best", "parts_missed", "--delta", "nan"], ["--delta", "nan"]),
    "a measure only the other policy reports": (
        {"policies": "[adaptive]", "key": "belts.input_nominal_in_s", "cycles": "[2.0, 3.0]"},
        ["--select-best", "thesis_slack_s", "--delta", "1",
         "--goal", "minimize"], ["--select-best", "thesis_slack_s"]),
    "no goal for a measure of no known direction": (
        {}, ["--select-best", "robot_busy_fraction", "--delta", "0.1"],
        ["--select-best", "robot_busy_fraction"]),
    "one replication": ({"replications": 1}, ["--select-best", "parts_missed", "--delta", "1"],
                        ["--select-best", "parts_missed"]),
}


@pytest.mark.parametrize("case", list(BEFORE), ids=list(BEFORE))
def test_refused_before_the_sweep_runs(tmp_path: Path, capsys, case: str) -> None:
    settings, options, named = BEFORE[case]
    out = tmp_path / "out"
    assert main(["sweep", str(_sweep(tmp_path, **settings)), "--out", str(out), *options]) == 2
    line = _line(capsys)
    assert all(word in line for word in named), line
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]


def test_a_count_that_never_varies_is_refused_not_chosen(tmp_path: Path, capsys) -> None:
    """Two cycles at which the fixed-cycle robot loses no part in any replication: KN has no
    variance to scale its eliminations by, and the selection is refused (the sweep's own
    results stay: they are right)."""
    out = tmp_path / "out"
    sweep = _sweep(tmp_path, cycles="[20.1, 20.2]", parts=2, replications=3)
    assert main(["sweep", str(sweep), "--out", str(out), "--workers", "1",
                 "--select-best", "parts_missed", "--delta", "0.5"]) == 2
    line = capsys.readouterr().err.strip().splitlines()[-1]
    assert "--select-best parts_missed" in line and "20.1" in line and "20.2" in line, line
    assert (out / "replications.csv").exists() and not (out / "selection.csv").exists()


def test_a_measure_no_run_gives_a_number_is_refused_not_chosen(tmp_path: Path, capsys) -> None:
    """mtbf_observed_s without failures is NaN in every run: not 'chosen' among NaN means."""
    out = tmp_path / "out"
    assert main(["sweep", str(_sweep(tmp_path, parts=5)), "--out", str(out), "--workers", "1",
                 "--select-best", "mtbf_observed_s", "--delta", "1", "--goal", "maximize"]) == 2
    line = capsys.readouterr().err.strip().splitlines()[-1]
    assert "--select-best mtbf_observed_s" in line and "nan" in line, line
    assert not (out / "selection.csv").exists()


STUDY = f"""base: {BASE}
set: {{run.parts: 20, controller.policy: adaptive}}
vary:
  belts.input_nominal_in_s: [2.0, 3.0]
objectives: [{{measure: parts_missed, goal: minimize}}]
trials: 2
replications: 2
"""


@pytest.mark.parametrize("select, where, value", [
    ("{measure: thesis_slack_s, delta: 1.0}", "select.measure", "thesis_slack_s"),
    ("{delta: .inf}", "select.delta", "inf"),
    # a measure of no known sense, on which no objective is: more or less better is not guessed
    ("{measure: robot_failures, delta: 1.0}", "select.measure", "robot_failures"),
])
def test_a_study_select_is_refused_before_any_trial(tmp_path: Path, capsys, select: str,
                                                    where: str, value: str) -> None:
    path = tmp_path / "study.yaml"
    path.write_text(STUDY + f"select: {select}\n")
    out = tmp_path / "out"
    assert main(["optimize", str(path), "--out", str(out)]) == 2
    line = _line(capsys)
    assert str(path) in line and where in line and value in line, line
    assert not out.exists()


def test_a_selection_measure_of_no_known_sense_takes_select_goal(tmp_path: Path) -> None:
    from cell.experiments.study import load_study, selection_goal

    path = tmp_path / "study.yaml"
    for goal in ("minimize", "maximize"):
        path.write_text(STUDY + f"select: {{measure: robot_failures, delta: 1.0, goal: {goal}}}\n")
        assert selection_goal(load_study(path)) == goal
    path.write_text(STUDY + "select: {measure: parts_missed, delta: 1.0}\n")
    assert selection_goal(load_study(path)) == "minimize"  # the objective's own goal
