"""The planner on the cell's R II and R IV, ``fastest_regime_times`` and ``cell mintime``."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from cell.arm.mintime.regimes import fastest_regime_times as planner_times
from cell.cli.main import main
from cell.scenario.catalog import BUILT_IN as SCENARIOS
from cell.scenario.schema import load_scenario
from cell.sim.scenario_values import geometry_of, motors_of, planner_bounds
from tests.prose import in_order

BASELINE = SCENARIOS / "baseline.yaml"

KIN = str(SCENARIOS / "mintime_kinematic.yaml")
BASE = str(BASELINE)
BASE_RATE = 0.4194527          # rad/s, robot.motors (calibrated, docs/model.md)


def fastest_regime_times(s):
    return planner_times(geometry_of(s), motors_of(s), planner_bounds(s))


def test_r4_kinematic_is_the_base_trapezoid():
    """R IV is 180° of base (docs/model.md) at the base's peak no-load rate ω, |q̈| ≤ a:
    T = π/ω + ω/a, the closed form of a trapezoid."""
    s = load_scenario(KIN)
    a = s.mintime.qddot_max_rad_s2[0]
    assert fastest_regime_times(s)["R4"] == pytest.approx(math.pi / BASE_RATE + BASE_RATE / a,
                                                          rel=1e-4)


def test_velocity_bounds_alone_give_the_thesis_constant_rate_time():
    """With (almost) unbounded acceleration the planner's R IV is the constant-rate time of
    Table 7.1's minimum cycle, π/ω = 7.4890 s (docs/model.md), plus the trapezoid's ramps
    ω/a: the closed form π/ω + ω/a, to the planner's convergence at its default grid."""
    s = load_scenario(KIN, {"mintime.qddot_max_rad_s2": [1e4] * 5})
    t = fastest_regime_times(s)["R4"]
    # the planner turns the base through π rad, the step table through 3534 whole steps
    # (1125π = 3534.29): the two differ by that rounding, 1e-4 relative
    assert math.pi / BASE_RATE == pytest.approx(7.4890, rel=1.5e-4)
    assert t == pytest.approx(math.pi / BASE_RATE + BASE_RATE / 1e4, rel=1e-5)


def test_dynamic_model_is_never_faster_than_the_velocity_bound():
    t = fastest_regime_times(load_scenario(BASE))
    assert t["R4"] >= math.pi / BASE_RATE
    assert t["R4"] < math.pi / BASE_RATE * 1.01


def test_times_are_cached_per_scenario():
    s = load_scenario(KIN)
    first = fastest_regime_times(s)
    n = len(planner_times)
    again = fastest_regime_times(s.with_overrides({"run.parts": 3}))   # irrelevant to the planner
    assert again == first and len(planner_times) == n
    other = fastest_regime_times(s.with_overrides({"mintime.qddot_max_rad_s2": [1.0] * 5}))
    assert other["R4"] > first["R4"] and len(planner_times) == n + 1


@pytest.mark.parametrize("scenario,torque", [(KIN, False), (BASE, True)])
def test_cli_writes_profile_and_summary(tmp_path, scenario, torque):
    out = tmp_path / "mt"
    assert main(["mintime", scenario, "--out", str(out)]) == 0
    doc = json.loads((out / "summary.json").read_text())
    assert sorted(p.name for p in out.iterdir()) == ["profile.csv", "summary.json"]
    assert set(doc["regimes"]) == {"R2", "R4"}
    assert doc["limits"]["torque"] is torque
    assert len(doc["limits"]["qdot_max_rad_s"]) == 5
    # the acceleration bounds are listed only where they applied (the kinematic planner)
    assert doc["limits"]["acceleration_bounds"] is not torque
    assert len(doc["limits"].get("qddot_max_rad_s2", [])) == (0 if torque else 5)
    frame = pd.read_csv(out / "profile.csv")
    assert list(frame.columns) == ["regime", "s", "t_s", "theta1_rad", "theta2_rad", "theta3_rad",
                                   "theta4_rad", "theta5_rad", "sdot", "sdot_limit"]
    assert (frame.groupby("regime").size() == 460).all()
    assert (frame["sdot"] <= frame["sdot_limit"] * (1 + 1e-9)).all()
    # The CSV's own profile gives the JSON's time: T = Σ 2Δs/(ṡ_i + ṡ_{i+1}), and t_s runs
    # from 0 to T, its steps those of the sum.
    for r, g in frame.groupby("regime"):
        sd, s, t_s = g["sdot"].to_numpy(), g["s"].to_numpy(), g["t_s"].to_numpy()
        steps = 2 * (s[1:] - s[:-1]) / (sd[1:] + sd[:-1])
        assert steps.sum() == pytest.approx(doc["regimes"][r]["time_s"], rel=1e-8)
        assert t_s[0] == 0 and t_s[-1] == pytest.approx(doc["regimes"][r]["time_s"], rel=1e-9)
        assert np.diff(t_s) == pytest.approx(steps, abs=1e-7)  # to the CSV's 10 digits


def test_cli_bad_dynamics_file_is_one_line_and_no_output(tmp_path, capsys):
    out = tmp_path / "mt"
    code = main(["mintime", BASE, "--set", "mintime.dynamics_file=missing.yaml", "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err
    assert "mintime.dynamics_file" in err and "missing.yaml" in err and "baseline.yaml" in err
    assert list(tmp_path.iterdir()) == []


def test_a_dynamics_file_is_checked_even_when_the_timing_does_not_use_it(tmp_path, capsys):
    out = tmp_path / "run"
    code = main(["run", BASE, "--set", "robot.timing=constant-rate", "--set",
                 "mintime.dynamics_file=missing.yaml", "--set", "run.parts=5", "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err and "mintime.dynamics_file" in err
    assert list(tmp_path.iterdir()) == []


def test_a_copy_of_the_baseline_elsewhere_finds_the_built_in_dynamics(tmp_path):
    import json

    from cell.scenario import catalog

    copy = tmp_path / "mine.yaml"
    copy.write_bytes(catalog.path("baseline").read_bytes())
    for scenario, out in ((BASE, tmp_path / "theirs"), (copy, tmp_path / "mine")):
        assert main(["mintime", str(scenario), "--out", str(out)]) == 0
    ours = json.loads((tmp_path / "mine" / "summary.json").read_text())
    theirs = json.loads((tmp_path / "theirs" / "summary.json").read_text())
    assert ours["regimes"] == theirs["regimes"]
    # a file of that name beside the scenario is preferred to the built-in one
    (tmp_path / "microbot_dynamics.yaml").write_text("name: broken\n")
    assert main(["mintime", str(copy), "--out", str(tmp_path / "beside")]) != 0


def test_no_bounds_at_all_is_refused(tmp_path, capsys):
    code = main(["mintime", KIN, "--set", "mintime.acceleration_bounds=false",
                 "--out", str(tmp_path / "x")])
    assert code == 2 and "infinite acceleration" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["mt.csv", "mt.json"])
def test_out_is_a_directory_not_the_old_stem(tmp_path, capsys, name):
    """``--out x.csv`` (the old STEM form) is refused before any work, naming what --out is now."""
    code = main(["mintime", KIN, "--out", str(tmp_path / name)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "profile.csv and summary.json" in err
    assert list(tmp_path.iterdir()) == []


def test_rerun_replaces_the_set_and_foreign_files_are_kept(tmp_path, capsys):
    out = tmp_path / "mt"
    assert main(["mintime", KIN, "--set", "mintime.grid_points=50", "--out", str(out)]) == 0
    first = (out / "profile.csv").read_text()
    assert main(["mintime", KIN, "--set", "mintime.grid_points=60", "--out", str(out)]) == 0
    assert (out / "profile.csv").read_text() != first
    assert len(pd.read_csv(out / "profile.csv")) == 120
    (out / "notes.txt").write_text("mine")
    capsys.readouterr()
    assert main(["mintime", KIN, "--out", str(out)]) == 2
    assert "notes.txt" in capsys.readouterr().err and len(pd.read_csv(out / "profile.csv")) == 120


def test_acceleration_bounds_switched_off_make_their_values_a_warning(tmp_path, capsys):
    """The baseline plans without acceleration bounds: bounds given anyway change nothing
    (the same times) and the command says so; the defaults, or bounds in use, are not warned."""
    tiny = "mintime.qddot_max_rad_s2=[1e-9, 1e-9, 1e-9, 1e-9, 1e-9]"
    assert main(["mintime", "baseline", "--set", tiny, "--out", str(tmp_path / "a")]) == 0
    err = capsys.readouterr().err
    assert in_order(err, "warning: mintime.qddot_max_rad_s2", f"({[1e-9] * 5})", "no effect")
    assert main(["mintime", "baseline", "--out", str(tmp_path / "b")]) == 0
    assert "warning" not in capsys.readouterr().err
    a, b = (json.loads((tmp_path / d / "summary.json").read_text()) for d in "ab")
    assert a == b  # the same motion, and the unused bounds are not listed as limits
    assert main(["mintime", "baseline", "--set", "mintime.acceleration_bounds=true", "--set",
                 "mintime.qddot_max_rad_s2=[3, 3, 5, 9, 9]", "--out", str(tmp_path / "c")]) == 0
    assert "warning" not in capsys.readouterr().err
