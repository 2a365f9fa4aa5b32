"""The energy of the arm's motion (cell.arm.energy) against independent facts: conservation
of energy without friction (net work = change of potential plus kinetic energy, the potential
from the forward kinematics, not the dynamics), the weight of a lifted part, the closed form
of a single joint turning a known inertia, and the drives' electrical bookkeeping."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.arm.dynamics import IN, OZ, DynamicsModel, Electrical, Links, chain
from cell.arm.energy import ArmEnergy, JointWork, Moves, PlannedLeg, planned_legs, step_positions
from cell.arm.kinematics import DH_ALPHA, a_matrix, hand_length
from cell.arm.mintime.regimes import plan_regimes
from cell.arm.steptable import SEGMENTS, StepTable
from cell.plumbing.errors import ScenarioError
from cell.scenario.catalog import BUILT_IN as SCENARIOS
from cell.scenario.dynamics_file import load_dynamics
from cell.scenario.schema import load_scenario
from cell.sim.scenario_values import geometry_of, motors_of, planner_bounds

MODEL = load_dynamics(SCENARIOS / "microbot_dynamics.yaml")
SCENARIO = load_scenario(SCENARIOS / "baseline.yaml")
GEOMETRY = geometry_of(SCENARIO)
MOTORS = motors_of(SCENARIO)
TABLE = StepTable.solve(GEOMETRY, MOTORS)
#: The thesis's nominal cycle (docs/model.md "The nominal cycle"), 22.5872 s.
NOMINAL = {"r1_pre": 1.3525, "r1_post": 1.3768, "r2": 5.8672, "r3_pre": 2.0, "r3_post": 2.0052,
           "r4": 9.9855}


@pytest.fixture(scope="module")
def baseline():
    return ArmEnergy.build(TABLE, MODEL, GEOMETRY)


def frames(q, a_m):
    """World frames of links 1..5 from the DH matrices (metres, base z vertical)."""
    t, out = np.eye(4), []
    for i in range(5):
        t = t @ a_matrix(q[i], 0.0, a_m[i], DH_ALPHA[i])
        out.append(t)
    return out


def potential(ch, q):
    """Σ m g z of the link centres of mass (a payload is merged into link 5)."""
    return sum(ch.mass[i] * ch.gravity * (f[:3, :3] @ ch.com[i] + f[:3, 3])[2]
               for i, f in enumerate(frames(q, ch.a_m)))


def part_point(q, a_m, tcp_in):
    """Where the part rides: ``tcp_in`` out along the hand's approach axis (m)."""
    f = frames(q, a_m)[4]
    return f[:3, 3] + f[:3, 2] * tcp_in * IN


def rates_from(seed, scale, n):
    """(n,) move rates 1/t, t between 5 ms and 0.2 s, times ``scale``; row 0 unused."""
    r = np.random.default_rng(seed).uniform(5.0, 200.0, n) * scale
    r[0] = 0.0
    return r


def net(moves, rates, friction=False):
    up, down, change = moves.work(rates, friction)
    return float((up - down + change).sum())


def velocities():
    """Six stretch velocities (in/s) from a walking pace to beyond the motors' limits."""
    v = st.floats(0.5, 12.0)
    return st.fixed_dictionaries({name: v for name in SEGMENTS})


@pytest.fixture(scope="module")
def empty_loop():
    """K → B along R IV and back to K by B → F → G → K, empty."""
    q = step_positions(TABLE)
    r4 = TABLE.regime_points("R4")
    path = np.vstack([q[r4], q[1:r4[0] + 1]])
    empty = chain(MODEL, GEOMETRY.arm.l2, GEOMETRY.arm.l3)
    return Moves.build(path, [empty] * len(path))


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), scale=st.floats(0.05, 3.0))
def test_an_empty_loop_from_rest_to_rest_does_no_net_work(empty_loop, seed, scale):
    """K → B along R IV and back to K by B → F → G → K, empty, rest to rest, any move rates: with
    no friction the joints' net work is zero (gravity is conservative, kinetic energy returns)."""
    moves = empty_loop
    rates = rates_from(seed, scale, len(moves.dq))
    up, down, change = moves.work(rates, friction=False)
    assert (up + down).sum() > 0.05                     # the joints do work on the way
    assert net(moves, rates) == pytest.approx(0.0, abs=1e-9)
    # with friction the loop costs exactly the friction: Σ K Δq² / t
    expect = float((rates[:, None] * moves.viscous).sum())
    assert net(moves, rates, friction=True) == pytest.approx(expect, rel=1e-9, abs=1e-12)


@pytest.fixture(scope="module")
def higher_place():
    """The baseline cell with the part set down 2 in higher than it is picked, and 12 oz."""
    route = replace(GEOMETRY.route, place_height_in=3.0)
    g = replace(GEOMETRY, route=route, part_weight_oz=12.0)
    table = StepTable.solve(g, MOTORS)
    return g, table, ArmEnergy.build(table, MODEL, g)


@settings(max_examples=15, deadline=None)
@given(v=velocities())
def test_a_whole_transfer_without_friction_costs_the_parts_energy(higher_place, v):
    """B to B, rest to rest, at any stretch velocities, no friction: the joints' net work is the
    part's change of potential energy between pick (LO) and set-down (TD) plus its change of
    kinetic energy: the part enters the hand at LO and leaves it at TD at the hand's velocity
    (the move arriving there), so the arm gives it the difference.  The arm ends where it
    started, empty: its own energy returns to what it was."""
    g, table, ae = higher_place
    times = ae.times_at(v)
    work = ae.joint_work(times, friction=False)
    total = sum(float(w.net.sum()) for w in work.values())
    q, rates = step_positions(table), ae.move_rates(times)
    lo, td = table.path.lo, table.path.td
    tcp = float(hand_length(g.part_size_in, g.hand))
    a_m = chain(MODEL, g.arm.l2, g.arm.l3).a_m
    m = g.part_weight_oz * OZ

    def state(k):
        """Part position and velocity at point k, the arriving move's rates (central differences)."""
        h = 1e-6
        step = rates[k] * (q[k] - q[k - 1])
        vel = (part_point(q[k] + h * step, a_m, tcp) - part_point(q[k] - h * step, a_m, tcp)) / (2 * h)
        return part_point(q[k], a_m, tcp), vel

    (p_lo, v_lo), (p_td, v_td) = state(lo), state(td)
    assert p_td[2] - p_lo[2] == pytest.approx(2.0 * IN, abs=0.01 * IN)
    expect = m * MODEL.gravity_m_s2 * (p_td[2] - p_lo[2]) + 0.5 * m * (v_td @ v_td - v_lo @ v_lo)
    assert total == pytest.approx(expect, abs=1e-8)


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), scale=st.floats(0.05, 3.0),
       load_oz=st.floats(1.0, 16.0))
def test_lifting_the_part_costs_at_least_its_weight_times_the_height(baseline, seed, scale, load_oz):
    """LO → F, rest to rest, friction on: carrying the part costs exactly m g h more net work
    than the same lift empty (h from the forward kinematics), and its electrical energy at
    least m g h more."""
    q = step_positions(TABLE)
    rows = np.arange(TABLE.path.lo, TABLE.regime_points("R1")[-1] + 1)
    tcp = float(hand_length(GEOMETRY.part_size_in, GEOMETRY.hand))
    loaded = chain(MODEL, GEOMETRY.arm.l2, GEOMETRY.arm.l3, load_oz, tcp)
    empty = chain(MODEL, GEOMETRY.arm.l2, GEOMETRY.arm.l3)
    rates = rates_from(seed, scale, len(rows))
    work = {}
    for name, ch in (("loaded", loaded), ("empty", empty)):
        up, down, change = Moves.build(q[rows], [ch] * len(rows)).work(rates)
        work[name] = JointWork((up + np.maximum(change, 0)).sum(axis=0),
                               (down + np.maximum(-change, 0)).sum(axis=0), 1.0)
    h = part_point(q[rows[-1]], loaded.a_m, tcp)[2] - part_point(q[rows[0]], loaded.a_m, tcp)[2]
    assert h > 1.5 * IN
    mgh = load_oz * OZ * MODEL.gravity_m_s2 * h
    gained = float(work["loaded"].net.sum() - work["empty"].net.sum())
    assert gained == pytest.approx(mgh, rel=1e-7)
    extra = baseline.energy(work["loaded"]).electrical_j - baseline.energy(work["empty"]).electrical_j
    assert extra >= mgh * (1 - 1e-9)


def one_mass_model(mass_kg):
    """A point mass at the wrist centre, every other link massless; the drives as built."""
    return DynamicsModel(links=Links(mass_kg=(0.0, 0.0, 0.0, 0.0, mass_kg),
                                     com_m=((0, 0, 0),) * 5, inertia_kg_m2=((0, 0, 0),) * 5))


@pytest.mark.parametrize("mass_kg,sweep_rad,accel", [(0.5, np.pi / 2, 3.0), (2.0, 0.3, 40.0)])
def test_one_joint_at_constant_acceleration_gains_half_i_omega_squared(mass_kg, sweep_rad, accel):
    """The base turning a point mass at radius R from rest at constant acceleration: the torque
    is I θ̈ and the work ∫ τ dθ = I θ̈ Δθ = ½ I ω², I = m R² + N² J_m (the rotor, geared)."""
    model = one_mass_model(mass_kg)
    ch = chain(model, 7.0, 7.0)
    q0 = np.radians([10.0, 30.0, -60.0, -90.0, 0.0])
    radius = np.hypot(*frames(q0, ch.a_m)[4][:2, 3])
    inertia = mass_kg * radius ** 2 + model.drives.gear_ratio[0] ** 2 * model.drives.rotor_inertia_kg_m2[0]
    step = np.array([sweep_rad, 0, 0, 0, 0])
    s = np.linspace(0.0, 1.0, 201)
    sdot = np.sqrt(2 * accel * s)                 # s̈ = accel throughout, from rest
    time_s = np.sqrt(2 / accel)

    def spline(x, k):
        return q0 + np.outer(x, step) if k == 0 else np.outer(np.ones_like(x), step if k == 1 else 0 * step)

    leg = PlannedLeg.build(ch, spline, s, sdot, time_s)
    theta_dd = accel * sweep_rad
    assert leg.inertial[:, 0] == pytest.approx(inertia * theta_dd, rel=1e-9)
    work = leg.work(time_s, friction=False)
    omega = theta_dd * time_s
    assert work.supplied[0] == pytest.approx(0.5 * inertia * omega ** 2, rel=1e-9)
    assert work.supplied[0] == pytest.approx(inertia * theta_dd * sweep_rad, rel=1e-9)
    assert np.abs(work.net[1:]).max() < 1e-12 * work.supplied[0]   # the others hold still
    # the same motion slowed to twice its time: a quarter of the torque, a quarter of the work
    assert leg.work(2 * time_s, friction=False).supplied[0] == pytest.approx(omega ** 2 * inertia / 8)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2 ** 32 - 1), scale=st.floats(0.05, 3.0), mass_kg=st.floats(0.05, 3.0),
       recover=st.booleans())
def test_constant_rate_changes_of_speed_are_changes_of_kinetic_energy(baseline, seed, scale, mass_kg,
                                                                     recover):
    """Constant-rate timing, the base alone turning out and back through 90°, rest to rest: each
    instant change of rate from ω_a to ω_b costs ½ I (ω_b² − ω_a²); over the cycle they add up
    to nothing; the motors supply the increases; with braking dissipated the drives draw the
    standing draw plus the increases over the efficiency, with it recovered η × the decreases
    less."""
    model = one_mass_model(mass_kg)
    ch = chain(model, 7.0, 7.0)
    q0 = np.radians([0.0, 30.0, -60.0, -90.0, 0.0])
    radius = np.hypot(*frames(q0, ch.a_m)[4][:2, 3])
    inertia = mass_kg * radius ** 2 + model.drives.gear_ratio[0] ** 2 * model.drives.rotor_inertia_kg_m2[0]
    base = np.concatenate([np.linspace(0, np.pi / 2, 40), np.linspace(np.pi / 2, 0, 31)[1:]])
    q = np.tile(q0, (len(base), 1))
    q[:, 0] = base
    moves = Moves.build(q, [ch] * len(q))
    rates = rates_from(seed, scale, len(q))
    up, down, change = moves.work(rates, friction=False)
    omega = np.append(rates * moves.dq[:, 0], 0.0)       # ω of the move arriving at each point
    ke_steps = 0.5 * inertia * (omega[1:] ** 2 - omega[:-1] ** 2)
    assert change[:, 0] == pytest.approx(ke_steps, rel=1e-9, abs=1e-15)
    assert np.abs(change[:, 1:]).max() < 1e-12             # the other joints do not move
    assert np.abs(up + down).max() < 1e-12                  # no gravity, no friction in the base
    assert change.sum() == pytest.approx(0.0, abs=1e-12)
    supplied = np.maximum(ke_steps, 0).sum()
    work = JointWork(np.maximum(change, 0).sum(axis=0), np.maximum(-change, 0).sum(axis=0), 3.0)
    assert work.supplied.sum() == pytest.approx(supplied, rel=1e-9)
    electrical = replace(MODEL.electrical, recover_braking=recover)
    ae = replace(baseline, model=replace(MODEL, electrical=electrical))
    e = ae.energy(work)
    eta = electrical.motion_efficiency[0]
    standing = 3.0 * 5 * electrical.phases_on * electrical.supply_v ** 2 / electrical.winding_ohm[0]
    assert e.standing_j == pytest.approx(standing)
    assert e.mechanical_j == pytest.approx(0.0, abs=1e-12)
    recovered = eta * supplied if recover else 0.0
    assert e.electrical_j - e.standing_j == pytest.approx(supplied / eta - recovered)


def test_below_the_motor_limits_net_work_is_gravity_plus_friction_in_proportion_to_speed(baseline):
    """The decomposition docs/model.md gives: R IV ends at rest, so the kinetic energy it gives
    its moves returns, and its net work at tip velocity v is ΔPE + F v − (the kinetic energy
    R III's last move brings into K) while no move is motor-limited (below the base's peak
    rate)."""
    top = baseline.segments["r4"].max_tracking_velocity()
    nets = []
    for v in (0.3 * top, 0.6 * top, 0.9 * top):
        times = dict(NOMINAL, r4=baseline.segments["r4"].time(v))
        nets.append(float(baseline.joint_work(times)["r4"].net.sum()))
    assert nets[2] - nets[1] == pytest.approx(nets[1] - nets[0], rel=1e-6)
    ch = chain(MODEL, GEOMETRY.arm.l2, GEOMETRY.arm.l3)
    pts = TABLE.regime_points("R4")
    q = step_positions(TABLE)
    d_pe = potential(ch, q[pts[-1]]) - potential(ch, q[pts[0]])
    k = pts[0]
    arriving = baseline.move_rates(NOMINAL)[k] * (q[k] - q[k - 1])
    ke_in = 0.5 * arriving @ ch.inertia_matrix(q[k]) @ arriving
    assert ke_in > 0
    assert 2 * nets[0] - nets[1] == pytest.approx(d_pe - ke_in, abs=1e-9)   # the intercept, v = 0


def test_the_nominal_cycle_is_mostly_the_drives_standing_draw(baseline):
    """The thesis's nominal cycle: a joule or two of shaft work, and the drives' standing draw
    (30 W while the arm moves) more than 99 % of what they draw (docs/model.md)."""
    e = baseline.transfer(NOMINAL)
    assert e.time_s == pytest.approx(sum(NOMINAL.values()), rel=1e-4)
    assert e.standing_j == pytest.approx(30.0 * e.time_s)
    assert 0.1 < e.mechanical_j < e.supplied_j < 5.0
    assert e.mechanical_j == pytest.approx(e.supplied_j - e.braking_j)
    assert e.electrical_j == pytest.approx(e.standing_j + e.supplied_j / 0.5)
    assert e.standing_share > 0.99
    legs = baseline.legs(NOMINAL)
    assert sum(leg.electrical_j for leg in legs.values()) == pytest.approx(e.electrical_j)


def test_a_faster_r4_costs_more_work_and_less_standing(baseline):
    floor = baseline.segments["r4"].floor_s
    slow, fast = baseline.legs(NOMINAL)["r4"], baseline.legs(dict(NOMINAL, r4=floor))["r4"]
    assert fast.supplied_j > slow.supplied_j and fast.standing_j < slow.standing_j


@pytest.fixture(scope="module")
def planned():
    results = plan_regimes(GEOMETRY, MOTORS, planner_bounds(SCENARIO))
    return results, planned_legs(TABLE, MODEL, GEOMETRY, results)


def test_minimum_time_legs_from_rest_to_rest_cost_their_potential_energy(planned):
    """R II (with the part) and R IV (empty) as the planner moves them, rest to rest, no
    friction: net work = the change of potential energy (nil on these arcs at constant
    height), the kinetic energy the profile gives returning, to 1e-4 of the work done, the
    planner grid's accuracy; slowed down, the same."""
    results, legs = planned
    tcp = float(hand_length(GEOMETRY.part_size_in, GEOMETRY.hand))
    for name, regime, ch in (("r2", "R2", chain(MODEL, GEOMETRY.arm.l2, GEOMETRY.arm.l3,
                                                 GEOMETRY.part_weight_oz, tcp)),
                             ("r4", "R4", chain(MODEL, GEOMETRY.arm.l2, GEOMETRY.arm.l3))):
        leg = legs[name]
        q = results[regime].q
        d_pe = potential(ch, q[-1]) - potential(ch, q[0])
        fast = leg.work(leg.time_s, friction=False)
        scale = float(fast.supplied.sum() + fast.braking.sum())
        assert float(fast.net.sum()) == pytest.approx(d_pe, abs=1e-4 * scale)
        slow = leg.work(1.5 * leg.time_s, friction=False)
        assert float(slow.net.sum()) == pytest.approx(d_pe, abs=1e-4 * scale)
    ae = ArmEnergy.build(TABLE, MODEL, GEOMETRY, planned=legs)
    times = dict(NOMINAL, r2=legs["r2"].time_s, r4=legs["r4"].time_s)
    assert ae.transfer(times).time_s == pytest.approx(sum(times.values()), rel=1e-4)
    with pytest.raises(ValueError):
        ae.transfer(dict(times, r4=0.9 * legs["r4"].time_s))


@pytest.mark.parametrize("patch,key", [
    ({"motion_efficiency": [0.5, 0.5, 1.5, 0.5, 0.5]}, "electrical.motion_efficiency[2]"),
    ({"recover_braking": "yes"}, "electrical.recover_braking"),
    ({"winding_ohm": [36, 36, 0, 36, 36]}, "electrical.winding_ohm[2]"),
    ({"standing_w": 6}, "electrical.standing_w"),
])
def test_bad_electrical_values_name_file_key_and_value(tmp_path, patch, key):
    raw = yaml.safe_load((SCENARIOS / "microbot_dynamics.yaml").read_text())
    raw["electrical"].update(patch)
    f = tmp_path / "dyn.yaml"
    f.write_text(yaml.safe_dump(raw))
    with pytest.raises(ScenarioError) as err:
        load_dynamics(f)
    assert (err.value.file, err.value.key) == (str(f), key)


def test_the_files_electrical_block_is_read():
    """The built-in file's block is what the model carries (6 W standing per drive), and a
    file without the block gets the same values."""
    assert MODEL.electrical == Electrical()
    assert MODEL.electrical.standing_w() == pytest.approx([6.0] * 5)
