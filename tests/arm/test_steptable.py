"""Joint-step table and motor model against thesis §6.1 and docs/model.md's figures."""

import numpy as np
import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st

from cell.arm.motors import Motors, max_rates, min_move_times, move_times, velocity_for_time
from cell.arm.path import CellGeometry
from cell.arm.steptable import COLUMNS, StepTable
from cell.plumbing.errors import InfeasibleError
from cell.plumbing.output.atomic import write_csv

M = Motors()
T = StepTable.solve(CellGeometry(), M)


def test_r4_base_steps_are_1125_pi():
    r4 = T.regime_rows("R4")
    assert abs(T.steps[r4, 0].sum()) == pytest.approx(1125 * np.pi, rel=0.01)
    assert abs(abs(T.steps[r4, 0].sum()) - 1125 * np.pi) <= 1  # absolute positions: no drift


def test_r4_times_reproduce_the_thesis():
    """docs/model.md: R IV at the base's nominal rate 9.9855 s, at its maximum 7.489 s."""
    assert T.regime_min_time("R4", nominal=True) == pytest.approx(9.9855, rel=0.005)
    assert T.regime_min_time("R4") == pytest.approx(7.489, rel=0.005)
    # ... from which the thesis's minimum feasible cycle follows (Table 7.1, last row)
    min_cycle = 22.5872 - (T.regime_min_time("R4", nominal=True) - T.regime_min_time("R4"))
    assert min_cycle == pytest.approx(20.0907, abs=0.005)


def test_closed_cycle_returns_every_motor_home():
    np.testing.assert_array_equal(T.steps.sum(axis=0), 0)


def test_steps_follow_the_joint_angles():
    k = np.asarray(M.steps_per_rad)
    travel = np.abs(np.diff(T.path.q_rad, axis=0)) * k
    assert np.all(np.abs(np.abs(T.steps[1:]) - travel) <= 1.0)


def test_rates_linear_in_load():
    k = np.asarray(M.steps_per_rad)
    np.testing.assert_allclose(max_rates(0.0, M), np.asarray(M.max_rate_no_load_rad_s) * k)
    np.testing.assert_allclose(max_rates(16.0, M), np.asarray(M.max_rate_full_load_rad_s) * k)
    np.testing.assert_allclose(max_rates(8.0, M), (max_rates(0.0, M) + max_rates(16.0, M)) / 2)
    np.testing.assert_allclose(max_rates(4.0, M, 0.75), 0.75 * max_rates(4.0, M))
    # TeachMover base no-load 0.42 rad/s = 472.5 steps/s; the calibrated figure is within 0.2 %
    assert max_rates(0.0, M)[0] == pytest.approx(472.5, rel=0.002)


def test_move_time_is_set_by_the_slowest_joint():
    """§6.1: a requested tip velocity, unless a motor would exceed its rate."""
    steps = np.array([[100, 10, 0, 0, 0], [0, 0, 0, 0, 5]])
    tmin = min_move_times(steps, [0.0, 0.0], M)
    rates = max_rates(0.0, M)
    np.testing.assert_allclose(tmin, [100 / rates[0], 5 / rates[4]])
    t = move_times([1.0, 1.0], tmin, 10.0)
    np.testing.assert_allclose(t, [max(0.1, tmin[0]), max(0.1, tmin[1])])


@given(st.lists(st.tuples(st.floats(0.01, 1.0), st.floats(0.0, 0.5)), min_size=1, max_size=40),
       st.floats(0.05, 20.0))
def test_velocity_for_time_inverts_the_regime_time(moves, v):
    ell, tmin = map(np.array, zip(*moves))
    total = move_times(ell, tmin, v).sum()
    v_back = velocity_for_time(ell, tmin, total)
    np.testing.assert_allclose(move_times(ell, tmin, v_back).sum(), total, rtol=1e-9)
    if total > tmin.sum() * (1 + 1e-9):  # not motor-bound everywhere: v is unique
        assert v_back == pytest.approx(v, rel=1e-9)


def test_velocity_for_time_refuses_the_impossible():
    with pytest.raises(InfeasibleError, match="below the motors' minimum"):
        velocity_for_time([1.0, 1.0], [0.5, 0.5], 0.9)


def test_nominal_r4_velocity_is_table_7_1_first_row():
    """Vavg R IV at 22.5872 s = 3.5594 in/s (Table 7.1)."""
    r4 = T.regime_rows("R4")
    v = velocity_for_time(T.move_in[r4], T.peak_min_times[r4], 9.9855)
    assert v == pytest.approx(3.5594, abs=1e-4)


def test_frame_columns_and_rows():
    df = T.to_frame()
    assert list(df.columns) == COLUMNS
    assert len(df) == 460
    assert df.loc[0, ["steps1", "steps2", "steps3", "steps4", "steps5", "move_in"]].eq(0).all()
    assert set(df["regime"]) == {"R1", "R2", "R3", "R4"}
    assert df["event"].tolist().count("LO") == 1 and df["event"].tolist().count("TD") == 1


def test_csv_round_trip(tmp_path):
    out = tmp_path / "steps.csv"
    write_csv(T.to_frame(), out)
    df = pd.read_csv(out, keep_default_na=False)
    assert list(df.columns) == COLUMNS and len(df) == 460
    np.testing.assert_allclose(df["theta1_deg"], np.degrees(T.path.q_rad[:, 0]), rtol=1e-9)
