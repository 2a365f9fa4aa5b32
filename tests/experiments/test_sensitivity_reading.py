"""``cell sensitivity``'s reading: every measure asked for is read, in the study's order; a
negative index is said to be sampling noise around 0; a measure no run of the study reports
(NaN in every run) is refused before any work, not given indices of 0 (issue 35)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cell.cli.main import main
from cell.experiments.study import load_study
from cell.reporting.sensitivity_report import negative_indices, negative_note, reading

BASE = Path(__file__).resolve().parents[2] / "scenarios" / "baseline.yaml"
KEYS = ("belts.input_nominal_in_s", "belts.input_length_in")


def study_file(tmp_path: Path, measures: list[str], policies: str = "[adaptive]") -> Path:
    path = tmp_path / "s.yaml"
    path.write_text(f"base: {BASE}\nset: {{run.parts: 20}}\npolicies: {policies}\n"
                    f"measures: [{', '.join(measures)}]\nreplications: 2\n"
                    "morris: {trajectories: 2}\nsobol: {samples: 2}\n"
                    f"vary: {{{KEYS[0]}: [2.0, 3.0], {KEYS[1]}: [110, 160]}}\n")
    return path


def tables(measures: list[str], s1: float = 0.5, half: float = 0.1):
    sobol = pd.DataFrame([{"policy": "adaptive", "measure": m, "key": k, "S1": s1,
                           "S1_ci95": half, "ST": 0.6, "ST_ci95": half}
                          for m in measures for k in KEYS])
    points = pd.DataFrame({"design": ["sobol"] * 3, **{f"adaptive/{m}": [1.0, 2.0, 3.0]
                                                       for m in measures}})
    return sobol, points


def test_every_measure_asked_for_is_read_in_the_studys_order(tmp_path):
    """parts_delivered and r1_nominal_s are not among the report's headline words: the
    reading still reads them, first measure first."""
    asked = ["parts_delivered", "r1_nominal_s", "parts_missed"]
    study = load_study(study_file(tmp_path, asked), corners=False)
    sobol, points = tables(asked)
    lines = reading(study, sobol, None, points, ["adaptive"])
    assert len(lines) == len(asked)
    assert "`parts_delivered`" in lines[0] and "`r1_nominal_s`" in lines[1]
    assert KEYS[0] in lines[0]  # its movers named


@pytest.mark.parametrize(("s1", "half", "count", "covered"), [
    (0.4, 0.1, 0, 0),  # none below 0
    (-0.029, 0.128, 2, 2),  # the "S1 -0.029 ± 0.128": noise, its interval covers 0
    (-0.3, 0.1, 2, 0),  # an interval short of 0: too few samples
])
def test_negative_indices_are_counted_and_said_to_cover_zero(s1, half, count, covered):
    sobol, _ = tables(["parts_missed"], s1, half)
    n, cov, lowest = negative_indices(sobol)
    assert (n, cov) == (count, covered)
    if count:
        assert lowest == ("S1", s1, half)
        assert len(negative_note(sobol)) == 2  # the note, then a blank line before the table
    else:
        assert lowest is None and negative_note(sobol) == []


def test_the_committed_report_says_what_its_negative_indices_are():
    root = Path(__file__).resolve().parents[2] / "reports" / "sensitivity"
    sobol = pd.read_csv(root / "sobol.csv")
    n, covered, lowest = negative_indices(sobol)
    assert n and lowest is not None  # the committed study has some
    text = (root / "report.md").read_text(encoding="utf-8")
    assert negative_note(sobol)[0] in text
    assert np.isclose(lowest[1], sobol[["S1", "ST"]].to_numpy().min())


def test_a_measure_no_policy_run_reports_is_refused_before_any_work(tmp_path, capsys):
    """thesis_slack_s is the fixed-cycle robot's alone: with the adaptive robot only it is NaN
    in every run; refused with its key and value, exit 2, nothing written."""
    out = tmp_path / "out"
    path = study_file(tmp_path, ["parts_missed", "thesis_slack_s"])
    assert main(["sensitivity", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert "measures[1]" in err and "thesis_slack_s" in err and str(path.name) in err
    assert not out.exists()
    both = study_file(tmp_path, ["thesis_slack_s"], "[adaptive, non-adaptive]")
    assert load_study(both, corners=False).settings.measures == ["thesis_slack_s"]


def test_no_index_for_a_measure_no_run_gives():
    """A column NaN at every point (the policy does not report it) gets NaN indices, not 0."""
    from cell.experiments.sensitivity import sobol_design, sobol_indices
    from cell.experiments.study import Param

    d = sobol_design([Param("a", 0.0, 1.0), Param("b", 0.0, 1.0)], 8, seed=1)
    res = sobol_indices(d, np.full(len(d.points), np.nan), seed=1)
    assert all(np.isnan(res[k]).all() for k in ("S1", "S1_conf", "ST", "ST_conf"))


def test_a_measure_one_policy_gives_has_indices_for_that_policy_alone(tmp_path, capsys):
    out = tmp_path / "out"
    path = study_file(tmp_path, ["parts_missed", "thesis_slack_s"], "[adaptive, non-adaptive]")
    assert main(["sensitivity", str(path), "--out", str(out), "--workers", "1"]) == 0
    sobol = pd.read_csv(out / "sobol.csv")
    morris = pd.read_csv(out / "morris.csv")
    for frame in (sobol, morris):
        slack = frame[frame["measure"] == "thesis_slack_s"]
        assert set(slack["policy"]) == {"non-adaptive"}  # the adaptive robot gives none
        assert not frame.drop(columns=["policy", "measure", "key"]).isna().any().any()
    report = (out / "report.md").read_text(encoding="utf-8")
    assert "nan" not in report.lower()
    assert "`thesis_slack_s`, adaptive**: n/a" in report
