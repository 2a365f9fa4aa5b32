"""The MICROBOT rigid-body model against independent facts: the potential
energy's gradient, the kinetic energy from finite-difference velocities, the
Christoffel form of the Coriolis terms, and the thesis's rate-against-load line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from cell.arm.dynamics import IN, OZ, DynamicsModel, chain, free_speed
from cell.arm.kinematics import DH_ALPHA, a_matrix
from cell.plumbing.errors import ScenarioError
from cell.scenario.dynamics_file import load_dynamics
from cell.scenario.schema import default_scenario

MODEL = load_dynamics(Path(__file__).parents[2] / "scenarios" / "microbot_dynamics.yaml")
CH = chain(MODEL, 7.0, 7.0, payload_oz=4.0, tcp_in=3.55)
RNG = np.random.default_rng(7)
QS = [np.radians([30, 40, -70, -120, 20]), RNG.uniform(-1.5, 1.5, 5), RNG.uniform(-1.5, 1.5, 5)]


def frames(q):
    """World frames of links 1..5 from the lead's DH matrices (metres)."""
    t = np.eye(4)
    out = []
    for i in range(5):
        t = t @ a_matrix(q[i], 0.0, CH.a_m[i], DH_ALPHA[i])
        out.append(t)
    return out


def com_world(q):
    return [f[:3, :3] @ CH.com[i] + f[:3, 3] for i, f in enumerate(frames(q))]


def potential(q):
    return sum(CH.mass[i] * CH.gravity * c[2] for i, c in enumerate(com_world(q)))


def mass_matrix_fd(q, h=1e-6):
    """Σ m Jvᵀ Jv + Jωᵀ R I Rᵀ Jω (+ rotor), Jacobians by central differences of the frames."""
    m = np.diag(CH.rotor).astype(float)
    for i in range(5):
        jv = np.zeros((3, 5))
        jw = np.zeros((3, 5))
        for k in range(5):
            dq = np.zeros(5)
            dq[k] = h
            cp, cm = com_world(q + dq)[i], com_world(q - dq)[i]
            rp, rm, r0 = frames(q + dq)[i][:3, :3], frames(q - dq)[i][:3, :3], frames(q)[i][:3, :3]
            jv[:, k] = (cp - cm) / (2 * h)
            w = (rp - rm) / (2 * h) @ r0.T
            jw[:, k] = [w[2, 1], w[0, 2], w[1, 0]]
        r0 = frames(q)[i][:3, :3]
        m += CH.mass[i] * jv.T @ jv + jw.T @ r0 @ CH.inertia[i] @ r0.T @ jw
    return m


@pytest.mark.parametrize("q", QS)
def test_gravity_is_the_gradient_of_potential_energy(q):
    h = 1e-6
    grad = [(potential(q + h * e) - potential(q - h * e)) / (2 * h) for e in np.eye(5)]
    assert CH.rnea(q, np.zeros(5), np.zeros(5), friction=False) == pytest.approx(grad, abs=1e-7)


@pytest.mark.parametrize("q", QS)
def test_inertia_matrix_matches_kinetic_energy(q):
    m = CH.inertia_matrix(q)
    assert m == pytest.approx(m.T, abs=1e-12)
    assert np.all(np.linalg.eigvalsh(m) > 0)
    assert m == pytest.approx(mass_matrix_fd(q), abs=1e-7)


@pytest.mark.parametrize("q", QS)
def test_coriolis_is_the_christoffel_form(q):
    """c(q)(q̇, q̇) = Ṁ q̇ − ½ ∂(q̇ᵀ M q̇)/∂q (Lagrange), by finite differences of M."""
    qd = RNG.uniform(-1, 1, 5)
    h = 1e-6
    dm = [(CH.inertia_matrix(q + h * e) - CH.inertia_matrix(q - h * e)) / (2 * h) for e in np.eye(5)]
    mdot = sum(qd[k] * dm[k] for k in range(5))
    expect = mdot @ qd - 0.5 * np.array([qd @ dm[k] @ qd for k in range(5)])
    got = CH.rnea(q, qd, np.zeros(5), friction=False, gravity=False)
    assert got == pytest.approx(expect, abs=1e-7)


def test_batched_equals_single():
    q = np.array(QS)
    qd = RNG.uniform(-1, 1, q.shape)
    qdd = RNG.uniform(-1, 1, q.shape)
    batch = CH.rnea(q, qd, qdd)
    for i in range(len(q)):
        assert batch[i] == pytest.approx(CH.rnea(q[i], qd[i], qdd[i]), rel=1e-12, abs=1e-14)


@pytest.mark.parametrize("joint,rate", [(1, 0.15), (2, 0.23), (3, 1.31)])
def test_torque_lines_reproduce_the_full_load_rates(joint, rate):
    """Thesis §6.1 / docs/model.md: the top rate is linear in the load.  On each drive's line,
    the speed at which the spare torque equals the 1 lb payload's torque at full
    horizontal reach is the TeachMover's full-load rate (estimates: within 15 %)."""
    motors = default_scenario().robot.motors
    wf = free_speed(MODEL, motors.max_rate_no_load_rad_s)[joint]
    tau_s = MODEL.drives.stall_torque_nm[joint]
    k = MODEL.drives.viscous_nm_s_rad[joint]
    q = np.radians([0.0, 0.0, 0.0, -90.0, 0.0])    # arm and hand straight out, horizontal
    heavy = chain(MODEL, 7.0, 7.0, payload_oz=16.0, tcp_in=3.55)
    light = chain(MODEL, 7.0, 7.0)
    z = np.zeros(5)
    load = abs(heavy.rnea(q, z, z)[joint] - light.rnea(q, z, z)[joint])
    assert load == pytest.approx(16 * OZ * 9.80665 * {1: 17.55, 2: 10.55, 3: 3.55}[joint] * IN,
                                 rel=0.01)
    speed = (tau_s - load) / (tau_s / wf + k)      # τ_s (1 − ω/ω_f) = K ω + load
    assert speed == pytest.approx(rate, rel=0.15)


def test_free_speed_holds_the_no_load_rate():
    w0 = np.array(default_scenario().robot.motors.max_rate_no_load_rad_s)
    wf = free_speed(MODEL, w0)
    tau_s = np.array(MODEL.drives.stall_torque_nm)
    k = np.array(MODEL.drives.viscous_nm_s_rad)
    assert tau_s * (1 - w0 / wf) == pytest.approx(k * w0)


@pytest.mark.parametrize("patch,key", [
    ({"links": {"mass_kg": [1, 1, -1, 1, 1]}}, "links.mass_kg[2]"),
    ({"drives": {"stall_torque_nm": [1, 1, 1, 1]}}, "drives.stall_torque_nm"),
    ({"drives": {"gearratio": 3}}, "drives.gearratio"),
])
def test_bad_values_name_file_key_and_value(tmp_path, patch, key):
    raw = yaml.safe_load((Path(__file__).parents[2] / "scenarios" / "microbot_dynamics.yaml").read_text())
    for sec, vals in patch.items():
        raw[sec].update(vals)
    f = tmp_path / "dyn.yaml"
    f.write_text(yaml.safe_dump(raw))
    with pytest.raises(ScenarioError) as err:
        load_dynamics(f)
    assert str(f) in str(err.value) and key in str(err.value)
    assert "\n" not in str(err.value)


def test_file_values_are_the_defaults():
    assert MODEL == DynamicsModel(name=MODEL.name, description=MODEL.description)
