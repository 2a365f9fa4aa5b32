"""Study files (``cell optimize``, ``cell sensitivity``) given bad values: one line naming the
file, the key and the value, exit 2, nothing written, before any point is run."""

from __future__ import annotations

from pathlib import Path

import pytest

from .harness import cli, refused

BASELINE = Path(__file__).resolve().parents[2] / "scenarios" / "baseline.yaml"
RANGE = "belts.input_nominal_in_s: [2.0, 3.0]"
#: A small sensitivity study: (keys + 1) x 2 Morris points, (keys + 2) x 2 Sobol points, 5 parts.
SMALL = "morris: {trajectories: 2}\nsobol: {samples: 2}\n"


def study(tmp_path: Path, text: str, vary: str = RANGE) -> Path:
    path = tmp_path / "study.yaml"
    path.write_text(f"base: {BASELINE}\nset: {{run.parts: 5}}\nreplications: 1\ntrials: 2\n"
                    f"measures: [parts_missed]\nobjectives: [{{measure: parts_missed, goal: minimize}}]\n"
                    f"vary: {{{vary}}}\n{text}", encoding="utf-8")
    return path


#: (id, command, the study's extra text, what it varies, words the refusal must hold)
CASES = [
    # a key of a section the base leaves out (no failures:): the key alone makes no section
    ("failures key, base without failures, sensitivity", "sensitivity", SMALL,
     "failures.robot.time_to_failure.params.scale: [100, 1000]",
     ("vary.failures.robot.time_to_failure.params.scale", "100", "failures")),
    ("failures key, base without failures, optimize", "optimize", "",
     "failures.maintenance.every_h: [1, 8]", ("vary.failures.maintenance.every_h", "1", "failures")),
    # no bound on simulated work: Morris's design bounded as Sobol's, by its points
    ("a billion Morris trajectories", "sensitivity", "morris: {trajectories: 1000000000}\n", RANGE,
     ("morris.trajectories", "1000000000")),
    ("2**40 Sobol samples", "sensitivity", "sobol: {samples: 1099511627776}\n", RANGE,
     ("sobol.samples", "1099511627776")),
    # a quoted number is text, as in a scenario
    ("quoted trajectories", "sensitivity", "morris: {trajectories: '10'}\n", RANGE,
     ("morris.trajectories", "'10'")),
    ("quoted delta", "optimize", "select: {delta: '0.5'}\n", RANGE, ("select.delta", "'0.5'")),
    ("a policy twice", "sensitivity", SMALL + "policies: [adaptive, adaptive]\n", RANGE,
     ("policies[1]", "adaptive")),
    ("a fractional step on a whole-number key", "optimize", "",
     "path.moves.R1: {low: 90, high: 100, step: 0.5}", ("vary.path.moves.R1.step", "0.5")),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_a_bad_study_is_refused_in_one_line(tmp_path: Path, case: tuple) -> None:
    _, command, text, vary, words = case
    path = study(tmp_path, text, vary)
    out = tmp_path / "out"
    refused(cli(command, path, "--out", out), str(path), *words, nothing_in=out)


def test_a_key_that_alone_makes_the_missing_section_is_varied(tmp_path: Path) -> None:
    """``failures.repair.crews`` alone is a whole failures: section (no equipment fails): the
    study is read, the key a whole number as the schema holds it, and each point's scenario
    has the section."""
    from cell.experiments.study import load_study

    s = load_study(study(tmp_path, SMALL, "failures.repair.crews: [1, 3]"))
    (param,) = s.params
    assert s.base.failures is None and param.whole and (param.low, param.high) == (1, 3)
    assert s.scenario({"failures.repair.crews": 2}).failures.repair.crews == 2


def test_an_empty_censoring_column_is_refused(tmp_path: Path) -> None:
    log = tmp_path / "ttf.csv"
    log.write_text("ttf_s,running\n" + "".join(f"{100 + 37 * i % 900},{i % 3 == 0:d}\n" for i in range(40)))
    out = tmp_path / "fit.yaml"
    refused(cli("fit", log, "--column", "ttf_s", "--as", "time_to_failure", "--censored", "",
                "--out", out), str(log), "--censored", "''", nothing_in=out)
