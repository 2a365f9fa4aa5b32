"""The phase-plane planner against closed forms (docs/model.md), its failure modes, its grid and
its repeatability."""

from __future__ import annotations

import hashlib
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.interpolate import CubicSpline

from cell.arm.mintime.planner import (
    PathRows,
    acceleration_rows,
    path_grid,
    plan,
    torque_rows,
    velocity_limit,
    velocity_rows,
)
from cell.plumbing.errors import CellError


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


# --------------------------------------------------------------------------- fast drives
def test_path_grid_is_uniform_in_the_middle_and_graded_toward_both_ends():
    for n in (50, 460, 3680):
        s = path_grid(n)
        h = np.diff(s)
        assert len(s) == n and s[0] == 0.0 and s[-1] == 1.0 and np.all(h > 0)
        mid = h[len(h) // 2]
        assert h[0] < 0.01 * mid and h[-1] < 0.01 * mid
        assert np.all(h <= mid * (1 + 1e-12))
        if n >= 460:                                    # no jumps: neighbours within 25 %
            assert np.all(h[1:] / h[:-1] < 1.25) and np.all(h[:-1] / h[1:] < 1.25)
    # refining: twice the points, about half the step everywhere
    a, b = path_grid(460), path_grid(919)
    for x in (1e-5, 1e-3, 0.01, 0.5, 0.99, 1 - 1e-5):
        ha, hb = np.diff(a)[np.searchsorted(a, x) - 1], np.diff(b)[np.searchsorted(b, x) - 1]
        assert 0.3 < hb / ha < 0.7


def _single_joint(s, length):
    n = len(s)
    return np.column_stack([length * s]), np.full((n, 1), length), np.zeros((n, 1))


def test_a_ramp_far_shorter_than_a_grid_step_is_still_timed_exactly():
    """One joint, 3 rad at ≤ 0.42 rad/s, |q̈| ≤ 1000 rad/s²: T = L/v + v/a, the ramps 1/70 of a
    uniform step.  The graded grid resolves them; a uniform grid of the same size times each
    ramp as one step at half speed, 0.4 % too slow."""
    length, v, a = 3.0, 0.42, 1000.0
    expect = length / v + v / a
    times = []
    for s in (path_grid(460), np.linspace(0.0, 1.0, 460)):
        _, dq, ddq = _single_joint(s, length)
        times.append(plan(PathRows.join(acceleration_rows(s, dq, ddq, [a]),
                                        velocity_rows(s, dq, [v]))).time_s)
    assert times[0] == pytest.approx(expect, rel=1e-5)
    assert times[1] > expect * 1.003


def _drive_time(length, inertia, viscous, slope, stall, v):
    """A joint J q̈ + K q̇ = τ on the line |τ + k_l q̇| ≤ τ_s, |q̇| ≤ v < ω∞ = τ_s/(K + k_l),
    rest to rest over L.  With k = K + k_l and T_c = J/k, full drive gives
    q̇ = ω∞ (1 − e^(−t/T_c)) and full braking q̇ = −ω∞ + (q̇0 + ω∞) e^(−t/T_c): accelerate to v,
    cruise, brake to rest."""
    k = viscous + slope
    w, tc = stall / k, inertia / k
    t_up = -tc * math.log1p(-v / w)
    t_down = tc * math.log1p(v / w)
    d_up, d_down = w * t_up - tc * v, tc * v - w * t_down
    return t_up + t_down + (length - d_up - d_down) / v


@pytest.mark.parametrize("inertia", [0.002, 0.02])
@pytest.mark.parametrize("fraction", [0.9, 0.999999])
def test_a_drive_on_its_torque_speed_line_meets_the_closed_form(inertia, fraction):
    """The dynamic model's case (docs/model.md): the drive reaches top speed in 0.3-3 ms, far inside
    one grid step, and the velocity bound sits at (or just under) the torque balance."""
    length, viscous, slope, stall = 1.0, 0.4, 6.0, 3.0
    v = fraction * stall / (viscous + slope)
    expect = _drive_time(length, inertia, viscous, slope, stall, v)

    def rnea(q, qd, qdd, friction=False, gravity=True):
        return inertia * qdd

    err = []
    for n in (460, 1840):
        s = path_grid(n)
        q, dq, ddq = _single_joint(s, length)
        rows = PathRows.join(torque_rows(s, q, dq, ddq, rnea, [stall], viscous=[viscous],
                                         line_slope=[slope]), velocity_rows(s, dq, [v]))
        err.append(abs(plan(rows).time_s - expect) / expect)
    assert err[0] < 5e-5
    assert err[1] < err[0] / 4          # second order: a quarter of the error or less


def test_a_stiff_drive_settles_on_its_torque_balance_at_any_step():
    """J = 2e-5: the drive reaches ω∞ = τ_s/(K + k_l) in microseconds, so at every grid step
    the torque bound swings from full drive to full braking around ω∞ (a stiff step: Heun's
    method overshoots).  No velocity bound: T = L/ω∞ + 2 T_c ln 2 (the closed form above with
    the cruise at ω∞, T_c = J/k).  On a uniform grid each ramp is one step at half speed:
    T = (L/ω∞)(n + 1)/(n − 1), and no step overshoots ω∞."""
    length, inertia, viscous, slope, stall = 1.0, 2e-5, 0.4, 6.0, 3.0
    k = viscous + slope
    top = stall / k

    def rnea(q, qd, qdd, friction=False, gravity=True):
        return inertia * qdd

    for s, expect in ((path_grid(460), length / top + 2 * inertia / k * math.log(2)),
                      (np.linspace(0.0, 1.0, 50), length / top * 51 / 49)):
        q, dq, ddq = _single_joint(s, length)
        p = plan(torque_rows(s, q, dq, ddq, rnea, [stall], viscous=[viscous], line_slope=[slope]))
        assert p.time_s == pytest.approx(expect, rel=1e-5)
        assert np.all(p.sdot * length <= top * (1 + 1e-6))


# --------------------------------------------------------------------------- repeatability
_PLAN_FROM_FILE = """
import hashlib, sys
import numpy as np
from cell.arm.mintime.planner import PathRows, plan
d = np.load(sys.argv[1])
p = plan(PathRows(*(d[k] for k in ("s", "a", "b", "e", "c", "lo", "hi", "sdot_max"))))
print(p.time_s.hex(), hashlib.sha256(p.sdot.tobytes()).hexdigest())
"""


def _avx512_features():
    """numpy's dispatched AVX-512 code paths this machine has (empty elsewhere)."""
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__

    return [f for f in __cpu_dispatch__ if (f.startswith("AVX512") or f == "X86_V4")
            and __cpu_features__.get(f)]


def test_a_plan_is_the_same_bit_for_bit_in_fresh_processes_and_without_avx512(tmp_path):
    """The same rows give the same time and profile, bit for bit, in fresh processes and
    with numpy's AVX-512 code paths switched off (where its transcendental functions round
    differently): the planner uses IEEE arithmetic and a correctly rounded sum only."""
    s = path_grid(460)
    sp = CubicSpline(np.linspace(0, 1, 7), np.column_stack([np.linspace(0, 2, 7) ** 2,
                                                             np.sin(np.linspace(0, 3, 7))]))
    q, dq, ddq = sp(s), sp(s, 1), sp(s, 2)

    def rnea(q, qd, qdd, friction=False, gravity=True):
        return 0.3 * qdd + 0.05 * qd * qd[..., ::-1] + (0.8 * np.cos(q) if gravity else 0.0)

    rows = PathRows.join(torque_rows(s, q, dq, ddq, rnea, [3.0, 2.0], viscous=[0.1, 0.2],
                                     line_slope=[1.0, 1.0]), velocity_rows(s, dq, [0.5, 0.6]))
    path = tmp_path / "rows.npz"
    np.savez(path, **{k: getattr(rows, k) for k in ("s", "a", "b", "e", "c", "lo", "hi",
                                                       "sdot_max")})
    envs = [{}, {}]
    if _avx512_features():
        envs.append({"NPY_DISABLE_CPU_FEATURES": " ".join(_avx512_features())})
    outs = [subprocess.run([sys.executable, "-c", _PLAN_FROM_FILE, str(path)], check=True,
                           capture_output=True, text=True, env={**os.environ, **e}).stdout
            for e in envs]
    here = plan(rows)
    assert outs[0].split() == [here.time_s.hex(), hashlib.sha256(here.sdot.tobytes()).hexdigest()]
    assert all(o == outs[0] for o in outs)


_CELL_TIMES = """
import json
from cell.sim.scenario_values import geometry_of, motors_of, planner_bounds
from cell.scenario.catalog import BUILT_IN
from cell.arm.mintime.regimes import plan_regimes
from cell.scenario.schema import load_scenario
s = load_scenario(BUILT_IN / "baseline.yaml")
res = plan_regimes(geometry_of(s), motors_of(s), planner_bounds(s))
print(json.dumps({r: x.profile.time_s.hex() for r, x in res.items()}))
"""


def test_the_cells_regime_times_repeat_bit_for_bit_in_fresh_processes():
    """A fresh process (its own hash seed, nothing cached) gives this process's times, bit for
    bit (one subprocess and this one: two processes, where two subprocesses cost twice)."""
    fresh = json.loads(subprocess.run([sys.executable, "-c", _CELL_TIMES], check=True,
                                      capture_output=True, text=True).stdout)
    printed: list[str] = []
    exec(_CELL_TIMES, {"print": printed.append})
    assert fresh == json.loads(printed[0]) and set(fresh) == {"R2", "R4"}
