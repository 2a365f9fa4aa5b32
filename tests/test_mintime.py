"""The phase-plane planner against closed forms (SPEC §9) and its failure modes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.interpolate import CubicSpline

from cell.errors import CellError
from cell.mintime.planner import PathRows, acceleration_rows, plan, torque_rows, velocity_limit, velocity_rows


def line(n, length, joints=1):
    s = np.linspace(0.0, 1.0, n)
    return s, np.full((n, joints), length), np.zeros((n, joints))


@settings(max_examples=20, deadline=None)
@given(st.floats(0.1, 10.0), st.floats(0.1, 10.0))
def test_acceleration_bound_only_is_bang_bang(length, a):
    """One joint, |q̈| ≤ a, rest to rest over L: T = 2√(L/a), one switch at L/2."""
    s, dq, ddq = line(460, length)
    p = plan(acceleration_rows(s, dq, ddq, [a]))
    assert p.time_s == pytest.approx(2 * math.sqrt(length / a), rel=1e-5)
    assert p.switching_s == [pytest.approx(0.5, abs=2 / 459)]


@settings(max_examples=20, deadline=None)
@given(st.floats(0.5, 10.0), st.floats(0.1, 2.0), st.floats(0.5, 10.0))
def test_velocity_and_acceleration_bounds_give_the_trapezoid(length, v, a):
    assume(v * v / (2 * a) / length > 5 / 459)   # the ramps span several grid steps
    s, dq, ddq = line(460, length)
    p = plan(PathRows.join(acceleration_rows(s, dq, ddq, [a]), velocity_rows(s, dq, [v])))
    if length > v * v / a:    # reaches the cruise speed: trapezoid
        expect = length / v + v / a
        ramp = v * v / (2 * a) / length
        assert p.switching_s[0] == pytest.approx(ramp, abs=2 / 459)
        assert p.switching_s[-1] == pytest.approx(1 - ramp, abs=2 / 459)
    else:                     # never does: triangle
        expect = 2 * math.sqrt(length / a)
    assert p.time_s == pytest.approx(expect, rel=2e-4)
    assert np.all(p.sdot * length <= v * (1 + 1e-12))


def test_a_jump_in_the_velocity_limit_is_met_by_braking_before_it():
    """ṡ ≤ 1 up to s = 0.5 and ≤ 0.5 after, |s̈| ≤ 1, rest to rest.  From rest ṡ² = 2s; the
    brake onto the step is ṡ² = 0.25 + 2(0.5 − s); they meet at s = 0.3125, below the first
    cap.  Then cruise at 0.5 until the final brake (0.125 of s).  Closed form below."""
    n = 2001
    s = np.linspace(0, 1, n)
    cap = np.where(s <= 0.5, 1.0, 0.5)
    rows = acceleration_rows(s, np.ones((n, 1)), np.zeros((n, 1)), [1.0])
    rows = PathRows(rows.s, rows.a, rows.b, rows.e, rows.c, rows.lo, rows.hi, cap)
    p = plan(rows)
    vp = math.sqrt(2 * 0.3125)
    expect = vp + (vp - 0.5) + (1 - 0.5 - 0.125) / 0.5 + 0.5
    assert p.time_s == pytest.approx(expect, rel=1e-3)
    assert np.all(p.sdot <= cap * (1 + 1e-12))
    assert p.switching_s[0] == pytest.approx(0.3125, abs=2e-3)


def test_zero_inertia_point_is_crossed():
    """A joint reversing mid-path (q' = 0 at s = 0.5): its acceleration row bounds ṡ alone
    there (|q''| ṡ² ≤ a), and the planner rides through without dividing by zero."""
    n = 461
    s = np.linspace(0, 1, n)
    dq = np.column_stack([-0.5 * np.pi * np.sin(np.pi * s), 2 * (s - 0.5)])
    ddq = np.column_stack([-0.5 * np.pi ** 2 * np.cos(np.pi * s), np.full(n, 2.0)])
    rows = PathRows.join(acceleration_rows(s, dq, ddq, [10.0, 0.5]), velocity_rows(s, dq, [5, 5]))
    limit = velocity_limit(rows)
    mid = n // 2
    assert dq[mid, 1] == 0.0
    # At s = 0.5 joint 1 has q'' = 0 and joint 2 has q' = 0: only |2 ṡ²| ≤ 0.5 and joint 1's pair remain.
    assert limit[mid] <= math.sqrt(0.5 / 2.0) + 1e-12
    p = plan(rows)
    assert np.isfinite(p.time_s) and p.time_s > 0
    u = np.diff(p.sdot ** 2) / (2 * np.diff(s))
    qdd = dq[:-1] * u[:, None] + ddq[:-1] * (p.sdot[:-1] ** 2)[:, None]
    assert np.all(np.abs(qdd) <= np.array([10.0, 0.5]) * 1.05)


def test_no_motion_possible_raises_a_clear_error():
    """A joint whose torque cannot hold gravity anywhere on the path."""
    n = 50
    s = np.linspace(0, 1, n)
    q = np.column_stack([s])
    def rnea(q, qd, qdd, friction=False, gravity=True):   # a pendulum, m g l = 2 N m, J = 1
        return qdd + (2.0 * np.cos(q) if gravity else 0.0)
    rows = torque_rows(s, q, np.ones((n, 1)), np.zeros((n, 1)), rnea, [1.0])
    with pytest.raises(CellError, match="no motion possible at s = "):
        plan(rows)


def test_top_speed_is_the_torque_balance():
    """One joint, J s̈ + K ṡ = τ on the line |τ + (τ_s/ω_f) ṡ| ≤ τ_s: the arm speeds up
    towards, and never past, ω = τ_s / (K + τ_s/ω_f) (a single-joint closed form)."""
    n = 460
    s = np.linspace(0, 1, n)
    q = np.column_stack([s])

    def rnea(q, qd, qdd, friction=False, gravity=True):
        return 0.02 * qdd

    rows = torque_rows(s, q, np.ones((n, 1)), np.zeros((n, 1)), rnea, [3.0],
                       viscous=[0.4], line_slope=[3.0 / 0.5])
    top = 3.0 / (0.4 + 6.0)
    p = plan(rows)
    assert p.sdot.max() == pytest.approx(top, rel=1e-3)
    assert p.sdot.max() <= top * (1 + 1e-9)


def test_spline_path_profile_respects_every_bound():
    sw = np.linspace(0, 1, 30)
    qw = np.column_stack([np.sin(2 * np.pi * sw), sw ** 2, np.cos(3 * sw)])
    sp = CubicSpline(sw, qw)
    s = np.linspace(0, 1, 2000)
    dq, ddq = sp(s, 1), sp(s, 2)
    v, a = np.array([1.0, 0.8, 0.6]), np.array([2.0, 1.5, 1.0])
    p = plan(PathRows.join(acceleration_rows(s, dq, ddq, a), velocity_rows(s, dq, v)))
    assert np.all(np.abs(dq * p.sdot[:, None]) <= v * (1 + 1e-9))
    u = np.diff(p.sdot ** 2) / (2 * np.diff(s))
    qdd = dq[:-1] * u[:, None] + ddq[:-1] * (p.sdot[:-1] ** 2)[:, None]
    assert np.all(np.abs(qdd) <= a * 1.02)
