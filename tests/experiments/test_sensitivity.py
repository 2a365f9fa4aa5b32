"""Sobol and Morris (cell.experiments.sensitivity, through SALib) against the Ishigami function's analytic
indices (SPEC §12), with a fourth input that has no effect."""

from __future__ import annotations

import numpy as np
import pytest

from cell.experiments.sensitivity import morris_design, morris_indices, sobol_design, sobol_indices
from cell.experiments.study import Param

A, B = 7.0, 0.1
S1 = [0.3139, 0.4424, 0.0, 0.0]
ST = [0.5576, 0.4424, 0.2437, 0.0]
PARAMS = [Param(f"x{i}", -np.pi, np.pi) for i in range(1, 4)] + [Param("dummy", 0.0, 1.0)]


def ishigami(x: np.ndarray) -> np.ndarray:
    return np.sin(x[:, 0]) + A * np.sin(x[:, 1]) ** 2 + B * x[:, 2] ** 4 * np.sin(x[:, 0])


def test_sobol_indices_of_ishigami_agree_with_the_analytic_values() -> None:
    d = sobol_design(PARAMS, 1024, seed=1)
    res = sobol_indices(d, ishigami(d.points), seed=1)
    assert np.allclose(res["S1"], S1, atol=0.05), res["S1"]
    assert np.allclose(res["ST"], ST, atol=0.05), res["ST"]
    # the key with no effect: both indices indistinguishable from 0 (within their intervals)
    assert abs(res["S1"][3]) <= res["S1_conf"][3] + 1e-12
    assert abs(res["ST"][3]) <= res["ST_conf"][3] + 1e-12


def test_morris_ranks_ishigami_and_gives_the_dummy_nothing() -> None:
    d = morris_design(PARAMS, 20, 4, seed=1)
    res = morris_indices(d, ishigami(d.points), 4, seed=1)
    assert res["mu_star"][3] == 0.0 and res["sigma"][3] == 0.0
    assert min(res["mu_star"][:3]) > 0


def test_a_measure_no_key_moves_has_zero_indices() -> None:
    d = sobol_design(PARAMS[:2], 16, seed=1)
    res = sobol_indices(d, np.full(len(d.points), 3.0), seed=1)
    assert not res["ST"].any() and not res["S1"].any()


def test_a_choice_cannot_be_analysed() -> None:
    with pytest.raises(ValueError, match="range"):
        sobol_design([Param("controller.policy", choices=("adaptive",))], 8, seed=1)


def test_the_results_do_not_depend_on_the_number_of_workers(tmp_path) -> None:
    """The same points, run here and in two worker processes: the same numbers, in order."""
    from pathlib import Path

    from cell.experiments.sensitivity import evaluate
    from cell.experiments.study import load_study
    from cell.plumbing.progress import Progress

    base = Path(__file__).resolve().parents[2] / "scenarios" / "baseline.yaml"
    path = tmp_path / "s.yaml"
    path.write_text(f"base: {base}\nset: {{run.parts: 30}}\npolicies: [adaptive, non-adaptive]\n"
                    "measures: [parts_missed, parts_per_hr_wallclock]\nreplications: 2\n"
                    "vary: {belts.input_nominal_in_s: [2.0, 3.0], belts.input_length_in: [110, 160]}\n")
    study = load_study(path)
    d = sobol_design(list(study.params), 2, seed=3)
    quiet = Progress(len(d.points), "t", "points", enabled=False)
    one = evaluate(study, d, ["adaptive", "non-adaptive"], ["parts_missed", "parts_per_hr_wallclock"],
                   1, quiet)
    two = evaluate(study, d, ["adaptive", "non-adaptive"], ["parts_missed", "parts_per_hr_wallclock"],
                   2, quiet)
    assert one.shape == (len(d.points), 5) and np.array_equal(one, two)
    assert (one[:, 4] > 0).all()  # the adaptive robot's advantage, column 'advantage'
