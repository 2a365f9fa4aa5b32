"""Agreement with TOPP-RA (the ``toppra`` package), an independent method, on the
same spline path, the same grid, the same bounds and the same time formula
(docs/model.md): within 0.5 % on the default grid, and both converging to the same value as
the grid is refined.  Then the cell's R II and R IV: the planner on the default grid
within 0.05 % of its converged value under every bound set the project uses.

"Converged" is a Richardson sequence: the planner on 460·2^k points, k = 0 … 4; its time
converges at second order (each doubling cuts the change about fourfold), so
T∞ = T₄ + (T₄ − T₃)/3.  toppra's forward pass keeps every x = ṡ² a hair inside its
controllable set (it subtracts max(1e-8, 1e-4 x) at each step, ``toppra.constants.TINY``),
which slows it a little more on every grid point: its most accurate grid here is a uniform
one of a few thousand points, and that is the independent reference.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from cell.arm.dynamics import chain
from cell.arm.mintime.planner import PathRows, acceleration_rows, path_grid, plan, torque_rows, velocity_rows
from cell.arm.mintime.reference import toppra_profile
from cell.arm.mintime.regimes import FREE_REGIMES, plan_regimes, regime_path
from cell.scenario.catalog import BUILT_IN as SCENARIOS
from cell.scenario.dynamics_file import load_dynamics
from cell.scenario.schema import load_scenario
from cell.sim.physics_checks import step_table
from cell.sim.scenario_values import geometry_of, motors_of, planner_bounds

SW = np.linspace(0, 1, 25)
# Joint 1 reverses twice (zero-inertia points at s = 0.25 and 0.75), the others do not.
KIN_PATH = np.column_stack([0.8 * np.sin(2 * np.pi * SW), 1.5 * SW, 0.3 * np.cos(3 * SW)])
V3, A3 = [1.0, 0.8, 0.6], [2.0, 1.5, 1.0]

# A MICROBOT motion near the R II pose: base sweeps 90°, the shoulder rises and comes
# back (reverses at s = 0.5), the elbow and wrist follow; gravity and inertia vary.
Q0 = np.radians([-45.0, 46.7, -109.5, -117.2, 90.0])
DYN_PATH = Q0 + np.column_stack([np.pi / 2 * SW, 0.4 * np.sin(np.pi * SW), -0.3 * SW,
                                 0.2 * np.sin(2 * np.pi * SW), 0.5 * SW])
MODEL = load_dynamics(SCENARIOS / "microbot_dynamics.yaml")
CHAIN = chain(MODEL, 7.0, 7.0, payload_oz=4.0, tcp_in=3.55)
TAU = np.array(MODEL.drives.stall_torque_nm)
# Velocity bounds 20 times the TeachMover's, so that the torques (not the velocities)
# shape most of the profile.
V5 = 20 * np.array([0.42, 0.36, 0.82, 2.02, 2.02])
DEFAULT = 460
RICHARDSON = [460 * 2 ** k for k in range(5)]


def on_the_grid(rnea, s_way, q_way, grid):
    """``rnea`` (friction left out) as toppra's torque constraint asks it: point by point,
    three calls a grid point (q, 0, 0), (q, 0, q'), (q, q', q'').  Those calls are answered
    from one batched evaluation on the same spline and grid (the same function, computed a
    grid at a time: a point-by-point call costs about 1 ms); any other call is computed as
    asked."""
    import toppra

    path = toppra.SplineInterpolator(np.asarray(s_way, float), np.asarray(q_way, float),
                                     bc_type="not-a-knot")
    grid = np.asarray(grid, float)
    q, qs, qss = path.eval(grid), path.evald(grid), path.evaldd(grid)
    zero = np.zeros_like(q)
    known = {}
    for args in ((q, zero, zero), (q, zero, qs), (q, qs, qss)):
        for i, row in enumerate(rnea(*args, friction=False)):
            known[tuple(a[i].tobytes() for a in args)] = row

    def inv_dyn(q, qd, qdd):
        key = tuple(np.asarray(a, float).tobytes() for a in (q, qd, qdd))
        return known[key] if key in known else rnea(q, qd, qdd, friction=False)

    return inv_dyn


def ours_kinematic(s):
    sp = CubicSpline(SW, KIN_PATH)
    dq, ddq = sp(s, 1), sp(s, 2)
    return plan(PathRows.join(acceleration_rows(s, dq, ddq, A3), velocity_rows(s, dq, V3))).time_s


def ours_torque(s):
    sp = CubicSpline(SW, DYN_PATH)
    q, dq, ddq = sp(s), sp(s, 1), sp(s, 2)
    return plan(PathRows.join(torque_rows(s, q, dq, ddq, CHAIN.rnea, TAU),
                              velocity_rows(s, dq, V5))).time_s


def rel(a, b):
    return abs(a - b) / b


def converged(times):
    """T∞ from the last two of a sequence on doubling grids (second order), after checking
    that the sequence has settled."""
    assert rel(times[-1], times[-2]) < 5e-6
    return times[-1] + (times[-1] - times[-2]) / 3


@pytest.fixture(scope="module")
def kinematic():
    return {"ours": [ours_kinematic(path_grid(n)) for n in RICHARDSON],
            "toppra": {n: toppra_profile(SW, KIN_PATH, path_grid(n), qdot_max=V3, qddot_max=A3)[1]
                       for n in (230, DEFAULT)},
            "toppra_fine": toppra_profile(SW, KIN_PATH, np.linspace(0, 1, 2000), qdot_max=V3,
                                          qddot_max=A3)[1]}


@pytest.fixture(scope="module")
def torque():
    return {"ours": [ours_torque(path_grid(n)) for n in RICHARDSON],
            "toppra": {n: toppra_profile(SW, DYN_PATH, path_grid(n), qdot_max=V5, tau_max=TAU,
                                         inv_dyn=on_the_grid(CHAIN.rnea, SW, DYN_PATH, path_grid(n)))[1]
                       for n in (230, DEFAULT, 920)}}


def test_velocity_and_acceleration_agree_with_toppra(kinematic):
    assert rel(kinematic["ours"][0], kinematic["toppra"][DEFAULT]) < 0.005


def test_velocity_and_acceleration_converge_to_toppra_on_a_fine_grid(kinematic):
    ref = kinematic["toppra_fine"]
    assert rel(kinematic["toppra"][230], ref) > rel(kinematic["toppra"][DEFAULT], ref)
    assert rel(converged(kinematic["ours"]), ref) < 2e-5
    assert rel(kinematic["ours"][0], ref) < 5e-4


def test_torque_agrees_with_toppra(torque):
    assert rel(torque["ours"][0], torque["toppra"][DEFAULT]) < 0.005


def test_torque_converges_together(torque):
    """toppra (first order here) closes in on the planner's converged time as its grid is
    refined; the planner is already within 0.01 % of it on the default grid."""
    t_inf = converged(torque["ours"])
    gaps = [rel(torque["toppra"][n], t_inf) for n in (230, DEFAULT, 920)]
    assert gaps[0] > gaps[1] > gaps[2]
    assert gaps[2] < 5e-4
    assert rel(torque["ours"][0], t_inf) < 1e-4


def test_torque_binds_on_this_path(torque):
    """The comparison is only a test of the dynamics if the torques, not just the
    velocities, shape the profile: without them the time is shorter."""
    s = path_grid(DEFAULT)
    sp = CubicSpline(SW, DYN_PATH)
    dq = sp(s, 1)
    big = np.full(5, 1e3)
    vel_only = plan(PathRows.join(acceleration_rows(s, dq, sp(s, 2), big),
                                  velocity_rows(s, dq, V5))).time_s
    assert torque["ours"][0] > vel_only * 1.2


# --------------------------------------------------------------------------- the cell
KIN, BASE = SCENARIOS / "mintime_kinematic.yaml", SCENARIOS / "baseline.yaml"


@pytest.fixture(scope="module")
def cell():
    """Each regime's times on the Richardson grids, for both bound sets, and its path."""
    out = {}
    for name in (KIN, BASE):
        sc = load_scenario(name)
        geometry, bounds = geometry_of(sc), planner_bounds(sc)
        runs = [plan_regimes(geometry, motors_of(sc), bounds, n) for n in RICHARDSON]
        for r in FREE_REGIMES:
            out[name, r] = {"times": [run[r].profile.time_s for run in runs],
                            "grid": runs[0][r].profile.s,
                            "path": regime_path(step_table(sc), r, geometry),
                            "vmax": runs[0][r].qdot_max_rad_s, "bounds": bounds,
                            "geometry": geometry}
    return out


@pytest.mark.parametrize("regime", FREE_REGIMES)
def test_cell_kinematic_converges_to_the_base_trapezoid(cell, regime):
    """Under the kinematic bounds R II (90°) and R IV (180°) are the base's trapezoid,
    T = L/ω + ω/a (the other joints idle or far from their bounds); toppra on the same
    default grid agrees within 0.5 %."""
    c = cell[KIN, regime]
    a = c["bounds"].qddot_max_rad_s2
    base = abs(c["path"].q_way[-1, 0] - c["path"].q_way[0, 0])
    expect = base / c["vmax"][0] + c["vmax"][0] / a[0]
    assert rel(converged(c["times"]), expect) < 1e-6
    assert rel(c["times"][0], expect) < 5e-4
    theirs = toppra_profile(c["path"].s_way, c["path"].q_way, c["grid"], qdot_max=c["vmax"],
                            qddot_max=a)[1]
    assert rel(c["times"][0], theirs) < 0.005


@pytest.mark.parametrize("regime", FREE_REGIMES)
def test_cell_dynamic_default_grid_is_within_0_05_percent_of_converged(cell, regime):
    """Under the baseline's dynamic model the drives reach top speed in milliseconds, far
    inside one grid step; the graded grid keeps the default 460 points within 0.05 %
    (a uniform grid of 460 is 0.3 % slow).  Never below the velocity bound alone."""
    c = cell[BASE, regime]
    t_inf = converged(c["times"])
    assert rel(c["times"][0], t_inf) < 5e-4
    base = abs(c["path"].q_way[-1, 0] - c["path"].q_way[0, 0])
    assert t_inf > base / c["vmax"][0]


def test_cell_torque_rows_agree_with_toppra_on_r4(cell):
    """The rigid-body torque bounds on the cell's own R IV path (the stall torques, without the
    torque-speed line and friction, which toppra cannot express): same grid, within 0.5 %."""
    c = cell[BASE, "R4"]
    rp, s = c["path"], c["grid"]
    ch = chain(MODEL, c["geometry"].arm.l2, c["geometry"].arm.l3, rp.load_oz, rp.tcp_in)
    sp = rp.spline()
    q, dq, ddq = sp(s), sp(s, 1), sp(s, 2)
    ours = plan(PathRows.join(torque_rows(s, q, dq, ddq, ch.rnea, TAU),
                              velocity_rows(s, dq, c["vmax"]))).time_s
    theirs = toppra_profile(rp.s_way, rp.q_way, s, qdot_max=c["vmax"], tau_max=TAU,
                            inv_dyn=on_the_grid(ch.rnea, rp.s_way, rp.q_way, s))[1]
    assert rel(ours, theirs) < 0.005
    assert ours > math.pi / c["vmax"][0]
