"""A rigid-body model of the MICROBOT arm for the minimum-time planner.

τ = J(q) q̈ + c(q)(q̇, q̇) + K q̇ + g(q)   (Shin & McKay 1983, eq. 1)

computed by the recursive Newton-Euler method on the arm's DH chain (thesis
Table 3.1, eq. 3.1-3.2), batched over many configurations, plus each drive's
reflected rotor inertia and viscous friction.  Parameters come from
``scenarios/microbot_dynamics.yaml``: every value there is an estimate with its
reasoning beside it (the thesis gives none).  SI units inside: kg, m, N·m.

Each drive's torque is bounded by a straight torque-speed line,
|τ + (τ_s/ω_f) q̇| ≤ τ_s, whose free speed ω_f is set so that, against the
viscous friction alone, the joint runs at exactly the TeachMover's no-load
rate (``robot.motors``): the thesis's linear rate-against-load model (§6.1).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from cell.arm.kinematics import DH_ALPHA
from cell.plumbing.errors import InfeasibleError
from cell.plumbing.types import Array, Five

Xyz = tuple[float, float, float]
Points5 = tuple[Xyz, Xyz, Xyz, Xyz, Xyz]

IN = 0.0254
"""Metres per inch."""
OZ = 0.028349523125
"""Kilograms per ounce (avoirdupois)."""


@dataclass(frozen=True)
class Links:
    """Mass properties of links 1-5, each in its own DH frame (frame i at the far end of link i)."""

    mass_kg: Five = (1.6, 0.30, 0.25, 0.10, 0.20)
    com_m: Points5 = ((0.0, -0.03, 0.0), (-0.0889, 0.0, 0.0), (-0.0889, 0.0, 0.0),
                      (0.0, 0.0, 0.0), (0.0, 0.0, 0.03))
    """Centre of mass of each link in its own frame."""
    inertia_kg_m2: Points5 = ((4e-3, 6e-3, 4e-3), (5e-5, 8e-4, 8e-4), (4e-5, 6.6e-4, 6.6e-4),
                              (1e-5, 1e-5, 1e-5), (6e-5, 6e-5, 3e-5))
    """Principal moments (Ixx, Iyy, Izz) about the centre of mass, along the frame's axes."""


@dataclass(frozen=True)
class Drives:
    """Stepper drives as seen at the joints."""

    gear_ratio: Five = (73.6, 73.6, 44.0, 15.8, 15.8)
    """Motor radians per joint radian."""
    rotor_inertia_kg_m2: Five = (5e-7, 5e-7, 5e-7, 5e-7, 5e-7)
    """Motor rotor inertia (motor side); the joint sees ratio² times this."""
    stall_torque_nm: Five = (3.1, 3.4, 1.66, 1.14, 1.14)
    """τ_s, joint side: torque at zero speed of the torque-speed line."""
    viscous_nm_s_rad: Five = (0.37, 0.47, 0.10, 0.028, 0.028)
    """K, joint side."""


@dataclass(frozen=True)
class Electrical:
    """What the stepper drives draw from their supply (``cell.arm.energy``; every value assumed).

    Each drive's phases carry the current its drive sets whatever the load (a stepper's torque
    comes from the rotor's lag behind the field, not from more current): the standing draw
    ``phases_on`` V²/R per drive while energised.  Shaft work is counted on top at
    ``motion_efficiency``; braking work is dissipated unless ``recover_braking``.
    """

    supply_v: float = 12.0
    """Drive supply voltage (unipolar L/R drive: the phase current is V/R)."""
    winding_ohm: Five = (36.0, 36.0, 36.0, 36.0, 36.0)
    """Resistance of one phase winding of each drive's motor."""
    phases_on: float = 1.5
    """Mean number of phases energised (half-stepping: one and two in turn)."""
    motion_efficiency: Five = (0.5, 0.5, 0.5, 0.5, 0.5)
    """Supply energy per joule of positive shaft work beyond the standing draw: 1/η."""
    recover_braking: bool = False
    """Whether braking work returns to the supply (at ``motion_efficiency``) or is dissipated."""

    def standing_w(self) -> Array:
        """(5,) each drive's standing draw in watts: phases_on · V² / R."""
        return self.phases_on * self.supply_v ** 2 / np.asarray(self.winding_ohm, float)


@dataclass(frozen=True)
class DynamicsModel:
    """The arm's rigid-body model: links, drives and gravity (a ``microbot_dynamics.yaml``)."""

    name: str = "microbot"
    description: str = ""
    gravity_m_s2: float = 9.80665
    links: Links = field(default_factory=Links)
    drives: Drives = field(default_factory=Drives)
    electrical: Electrical = field(default_factory=Electrical)


def _cross(a: Array, b: Array) -> Array:
    """a × b over the last axis (np.cross is slow on small arrays)."""
    a, b = np.asarray(a), np.asarray(b)
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


@dataclass(frozen=True)
class Chain:
    """The numeric chain for one payload: DH lengths, link masses, COMs, inertias, drives."""

    a_m: Array
    mass: Array
    com: Array
    """(5, 3)"""
    inertia: Array
    """(5, 3, 3) about the centre of mass, in the link frame."""
    rotor: Array
    """(5,) reflected rotor inertia ratio² J_m."""
    viscous: Array
    gravity: float

    def rnea(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike, *, friction: bool = True,
             gravity: bool = True) -> Array:
        """Joint torques (..., 5) for positions, velocities, accelerations (..., 5)."""
        q, qd, qdd = (np.asarray(v, float) for v in (q, qd, qdd))
        shape = np.broadcast_shapes(q.shape, qd.shape, qdd.shape)
        q, qd, qdd = (np.broadcast_to(v, shape).reshape(-1, 5) for v in (q, qd, qdd))
        n = len(q)
        ca, sa = np.cos(DH_ALPHA), np.sin(DH_ALPHA)
        c, s = np.cos(q), np.sin(q)
        # R_i: frame i relative to i-1, (n, 5, 3, 3)
        R = np.zeros((n, 5, 3, 3))
        R[..., 0, 0], R[..., 0, 1], R[..., 0, 2] = c, -s * ca, s * sa
        R[..., 1, 0], R[..., 1, 1], R[..., 1, 2] = s, c * ca, -c * sa
        R[..., 2, 1], R[..., 2, 2] = sa, ca
        pstar = np.zeros((5, 3))
        pstar[:, 0] = self.a_m
        w = np.zeros((n, 3))
        wd = np.zeros((n, 3))
        vd = np.zeros((n, 3))
        vd[:, 2] = self.gravity if gravity else 0.0
        F, N = [], []
        z = np.zeros((n, 3))
        for i in range(5):
            Rt = np.swapaxes(R[:, i], -1, -2)
            z[:, 2] = qd[:, i]
            wz = w + z
            wd_ = wd + _cross(w, z)
            wd_[:, 2] += qdd[:, i]
            w = np.einsum("nij,nj->ni", Rt, wz)
            wd = np.einsum("nij,nj->ni", Rt, wd_)
            vd = (np.einsum("nij,nj->ni", Rt, vd) + _cross(wd, pstar[i])
                  + _cross(w, _cross(w, pstar[i])))
            vc = vd + _cross(wd, self.com[i]) + _cross(w, _cross(w, self.com[i]))
            F.append(self.mass[i] * vc)
            Iw = w @ self.inertia[i].T
            N.append(wd @ self.inertia[i].T + _cross(w, Iw))
        tau = np.zeros((n, 5))
        f = np.zeros((n, 3))
        m = np.zeros((n, 3))
        for i in range(4, -1, -1):
            if i < 4:
                Rn = R[:, i + 1]
                f = np.einsum("nij,nj->ni", Rn, f)
                m = np.einsum("nij,nj->ni", Rn, m) + _cross(pstar[i], f)
            m = m + _cross(pstar[i] + self.com[i], F[i]) + N[i]
            f = f + F[i]
            tau[:, i] = np.einsum("ni,ni->n", m, R[:, i, 2, :])   # joint axis z_{i-1} in frame i
        tau += self.rotor * qdd
        if friction:
            tau += self.viscous * qd
        return tau.reshape(shape)

    def inertia_matrix(self, q: ArrayLike) -> Array:
        """J(q), (..., 5, 5), column by column from the Newton-Euler recursion."""
        q = np.asarray(q, float)
        eye = np.eye(5)
        cols = [self.rnea(q, np.zeros_like(q), np.broadcast_to(eye[k], q.shape),
                          friction=False, gravity=False) for k in range(5)]
        return np.stack(cols, axis=-1)


def chain(model: DynamicsModel, l2_in: float, l3_in: float, payload_oz: float = 0.0,
          tcp_in: float = 0.0) -> Chain:
    """The chain of ``model`` with a point payload ``tcp_in`` along the hand's approach axis."""
    lk, dr = model.links, model.drives
    mass = np.array(lk.mass_kg, float)
    com = np.array(lk.com_m, float)
    inertia = np.array([np.diag(v) for v in lk.inertia_kg_m2])
    mp = payload_oz * OZ
    if mp > 0:
        # A point mass at the tool centre, merged into link 5 (parallel-axis theorem).
        p = np.array([0.0, 0.0, tcp_in * IN])
        m5 = mass[4] + mp
        c5 = (mass[4] * com[4] + mp * p) / m5
        def shift(m: float, r: Array) -> Array:
            return m * (np.dot(r, r) * np.eye(3) - np.outer(r, r))
        inertia[4] = inertia[4] + shift(mass[4], com[4] - c5) + shift(mp, p - c5)
        mass[4], com[4] = m5, c5
    ratio = np.array(dr.gear_ratio, float)
    return Chain(np.array([0.0, l2_in * IN, l3_in * IN, 0.0, 0.0]), mass, com, inertia,
                 ratio ** 2 * np.array(dr.rotor_inertia_kg_m2, float),
                 np.array(dr.viscous_nm_s_rad, float), float(model.gravity_m_s2))


def free_speed(model: DynamicsModel, no_load_rad_s: ArrayLike) -> Array:
    """ω_f of each drive's line: τ_s (1 − ω0/ω_f) = K ω0, so friction alone holds it at ω0."""
    tau_s = np.array(model.drives.stall_torque_nm, float)
    k = np.array(model.drives.viscous_nm_s_rad, float)
    w0 = np.asarray(no_load_rad_s, float)
    spare = 1.0 - k * w0 / tau_s
    if np.any(spare <= 0):
        j = int(np.flatnonzero(spare <= 0)[0])
        raise InfeasibleError(f"drive {j + 1}: friction at the no-load rate exceeds the stall torque")
    return w0 / spare
