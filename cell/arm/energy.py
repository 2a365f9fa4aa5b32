"""The energy of the arm's motion (docs/model.md "Energy of the arm's motion").

Joint torques along each move of a transfer by inverse dynamics (the rigid-body model of
:mod:`cell.arm.dynamics`), mechanical power per joint, and what the stepper drives draw
(:class:`cell.arm.dynamics.Electrical`): a standing draw per drive for as long as the
transfer lasts, plus positive shaft work over an efficiency, less braking work if it is
recovered.

Constant-rate timing (the thesis's, §6.1): each move of the joint-step table runs at
constant joint rates, q̇ = Δq / t, t = max(ℓ / v, t_min), and the rates change instantly
between moves.  Within a move q̈ = 0, so τ = c(q)(q̇, q̇) + K q̇ + g(q), integrated by
Gauss-Legendre nodes.  Each instant change of rates from a to b at q is an impulse
J(q)(b − a) during which the rates change linearly: joint j does ½ (a_j + b_j) [J (b − a)]_j,
and together ½ bᵀJb − ½ aᵀJa, the change of kinetic energy (the limit of smoothing with an
ever higher acceleration).  The part changes hands at the hand's arriving velocity: the
impulse at lift-off uses the loaded arm, the one at touch-down the empty arm, so the part
brings its own kinetic energy in and takes it away.

Minimum-time timing (:mod:`cell.arm.mintime`): R II and R IV follow the planner's profile
rest to rest, slowed uniformly to the leg's time (inertial torques ∝ 1/k², friction ∝ 1/k).

Everything that depends on the path alone is computed once (:meth:`ArmEnergy.build`); a
transfer's energy from its six stretches' times is then a few numpy passes over the moves.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from cell.arm.dynamics import Chain, DynamicsModel, chain
from cell.arm.kinematics import hand_length
from cell.arm.mintime.regimes import RegimeResult, regime_path
from cell.arm.motors import Segment
from cell.arm.path import CellGeometry
from cell.arm.steptable import SEGMENTS, StepTable
from cell.plumbing.types import Array

#: Gauss-Legendre nodes per move (constant-rate timing): exact for the move's net work to
#: far below a microjoule, since a move turns each joint by at most a few hundredths of a radian.
NODES = 4

#: Stretches a minimum-time plan may replace (rest to rest), and the regime each one is.
PLANNED = {"r2": "R2", "r4": "R4"}


@dataclass(frozen=True)
class Energy:
    """The energy of some motion of the arm, in joules (sums over the five joints)."""

    time_s: float
    mechanical_j: float
    """Net shaft work Σ ∫ τ q̇ dt: what the arm's motion costs with nothing recovered or lost."""
    supplied_j: float
    """Positive work only, joint by joint: what the motors put in."""
    braking_j: float
    """Negative work, joint by joint, as a positive number: what the motors take out."""
    standing_j: float
    """The drives' standing draw over ``time_s``."""
    electrical_j: float
    """What the drives draw: the standing draw, plus supplied work over the efficiency, less
    recovered braking (``recover_braking``)."""

    @property
    def standing_share(self) -> float:
        """Share of the electrical energy that is the standing draw."""
        return self.standing_j / self.electrical_j if self.electrical_j else 0.0


@dataclass(frozen=True)
class JointWork:
    """Per-joint positive and negative work and the time of some motion."""

    supplied: Array
    """(5,) J."""
    braking: Array
    """(5,) J, positive."""
    time_s: float

    @property
    def net(self) -> Array:
        return self.supplied - self.braking


@dataclass(frozen=True)
class PlannedLeg:
    """A minimum-time profile's torque terms on its grid (one regime, rest to rest)."""

    s: Array
    dq: Array
    """(n, 5) q'(s)."""
    inertial: Array
    """(n, 5) J q̈ + c(q̇, q̇) at the planned speed: scales as 1/k² when slowed k times."""
    friction: Array
    """(n, 5) K q̇ at the planned speed: scales as 1/k."""
    gravity: Array
    time_s: float

    @classmethod
    def build(cls, ch: Chain, q_spline: Callable[[Array, int], Array], s: Array, sdot: Array,
              time_s: float) -> PlannedLeg:
        """From the planner's grid ``s`` and ṡ(s), and the regime's joint spline q(s)."""
        q, dq, ddq = (np.asarray(q_spline(s, k), float) for k in (0, 1, 2))
        sddot = 0.5 * np.gradient(sdot ** 2, s)
        qd = dq * sdot[:, None]
        qdd = dq * sddot[:, None] + ddq * (sdot ** 2)[:, None]
        inertial = ch.rnea(q, qd, qdd, friction=False, gravity=False)
        zero = np.zeros_like(q)
        gravity = ch.rnea(q, zero, zero, friction=False)
        return cls(np.asarray(s, float), dq, inertial, ch.viscous * qd, gravity, float(time_s))

    def work(self, time_s: float, friction: bool = True) -> JointWork:
        """The profile slowed uniformly to ``time_s`` (≥ its own time)."""
        k = time_s / self.time_s
        if k < 1 - 1e-9:
            raise ValueError(f"{time_s} s is shorter than the planned {self.time_s} s")
        tau = self.inertial / k ** 2 + self.gravity + (self.friction / k if friction else 0.0)
        density = self.dq * tau                  # dW/ds per joint: τ q̇ dt = τ q' ds
        return JointWork(_trapezoid(np.maximum(density, 0.0), self.s),
                         _trapezoid(np.maximum(-density, 0.0), self.s), float(time_s))


def _trapezoid(y: Array, s: Array) -> Array:
    return np.asarray(0.5 * ((y[1:] + y[:-1]) * np.diff(s)[:, None]).sum(axis=0))


@dataclass(frozen=True)
class Moves:
    """A run of constant-rate moves through joint positions q_0 … q_{N−1}, each move with the
    arm it moves (its chain: the payload differs before and after the part changes hands)."""

    dq: Array
    """(N, 5) joint travel of the move arriving at each point (row 0: zeros)."""
    weights: Array
    """(NODES,) Gauss-Legendre weights on [0, 1]."""
    coriolis: Array
    """(N, NODES, 5) Δq_j c_j(q(σ))(Δq, Δq): the velocity terms' work density at unit rate."""
    gravity: Array
    """(N, NODES, 5) Δq_j g_j(q(σ))."""
    viscous: Array
    """(N, 5) K_j Δq_j²."""
    j_arrive: Array
    """(N, 5) J(q_k) Δq_k, J of the arm as it leaves point k (the part taken or left)."""
    j_leave: Array
    """(N, 5) J(q_k) Δq_{k+1} (last row: zeros)."""

    @classmethod
    def build(cls, q: Array, chains: Sequence[Chain], nodes: int = NODES) -> Moves:
        """Moves through ``q`` (N, 5); ``chains[k]`` moves the arm into point k (k ≥ 1)."""
        q = np.asarray(q, float)
        n = len(q)
        if len(chains) != n or n < 2:
            raise ValueError("one chain per point (the first unused) and at least one move")
        dq = np.vstack([np.zeros((1, 5)), np.diff(q, axis=0)])
        x, w = np.polynomial.legendre.leggauss(nodes)
        sigma, weights = 0.5 * (x + 1.0), 0.5 * w
        coriolis, gravity = np.zeros((n, nodes, 5)), np.zeros((n, nodes, 5))
        j_arrive, j_leave = np.zeros((n, 5)), np.zeros((n, 5))
        after = np.minimum(np.arange(n) + 1, n - 1)      # the move leaving each point (or the last)
        nxt = np.vstack([dq[1:], np.zeros((1, 5))])
        for ch in {id(c): c for c in chains[1:]}.values():
            rows = np.array([m for m in range(1, n) if chains[m] is ch], dtype=np.intp)
            qs = q[rows - 1, None, :] + sigma[None, :, None] * dq[rows, None, :]
            vel = np.broadcast_to(dq[rows, None, :], qs.shape)
            zero = np.zeros_like(qs)
            coriolis[rows] = dq[rows, None, :] * ch.rnea(qs, vel, zero, friction=False,
                                                         gravity=False)
            gravity[rows] = dq[rows, None, :] * ch.rnea(qs, zero, zero, friction=False)
            viscous = ch.viscous
            pts = np.flatnonzero([chains[a] is ch for a in after])
            jm = ch.inertia_matrix(q[pts])
            j_arrive[pts] = np.einsum("nij,nj->ni", jm, dq[pts])
            j_leave[pts] = np.einsum("nij,nj->ni", jm, nxt[pts])
        return cls(dq, weights, coriolis, gravity, viscous * dq ** 2, j_arrive, j_leave)

    def work(self, rates: Array, friction: bool = True) -> tuple[Array, Array, Array]:
        """(within⁺, within⁻, change), each (N, 5), for the moves at ``rates`` (1/t, 0: no move):
        each joint's positive and negative work within the move arriving at each point, and
        its work in the instant change of rates at each point (rest before the first move and
        after the last)."""
        r = np.asarray(rates, float)
        # within the moves: τ q̇ dt = Δq_j τ_j(σ) dσ, τ = r² c + r K Δq + g
        dens = r[:, None, None] ** 2 * self.coriolis + self.gravity
        if friction:
            dens += (r[:, None] * self.viscous)[:, None, :]
        dens[r == 0] = 0.0
        up = np.maximum(dens, 0.0)
        within_up = np.einsum("nij,i->nj", up, self.weights)
        within_down = np.einsum("nij,i->nj", up - dens, self.weights)
        # the instant change at point k: from a = r_k Δq_k to b = r_{k+1} Δq_{k+1}
        r_next = np.append(r[1:], 0.0)
        a = r[:, None] * self.dq
        b = np.vstack([a[1:], np.zeros((1, 5))])
        change = 0.5 * (a + b) * (r_next[:, None] * self.j_leave - r[:, None] * self.j_arrive)
        return within_up, within_down, change


@dataclass(frozen=True)
class ArmEnergy:
    """Per-move quantities of one scenario's transfer path, built once; energies on demand."""

    model: DynamicsModel
    moves: Moves
    segments: dict[str, Segment]
    """Each stretch's moves (lengths and minimum times), as the simulation times them."""
    bounds: tuple[tuple[int, int], ...]
    """Each stretch's moves as a range of rows (the stretches follow one another)."""
    lengths_in: Array
    min_times_s: Array
    planned: dict[str, PlannedLeg]

    @classmethod
    def build(cls, table: StepTable, model: DynamicsModel, geometry: CellGeometry,
              planned: Mapping[str, PlannedLeg] | None = None, nodes: int = NODES) -> ArmEnergy:
        """The path of ``table`` under ``model``; ``planned``: stretches ("r2", "r4") that follow
        a minimum-time profile (see :func:`planned_legs`) instead of constant rates."""
        path = table.path
        tcp = np.asarray(hand_length(path.opening_in, geometry.hand), float)
        chains: dict[tuple[float, float], Chain] = {}

        def chain_of(move: int) -> Chain:
            load = float(path.load_oz[move])
            key = (load, float(tcp[move]) if load > 0 else 0.0)
            if key not in chains:
                chains[key] = chain(model, geometry.arm.l2, geometry.arm.l3, *key)
            return chains[key]

        moves = Moves.build(step_positions(table), [chain_of(max(m, 1)) for m in
                                                    range(path.n_points)], nodes)
        ell, tmin = table.velocity_lengths, table.peak_min_times
        rows = table.segment_rows()
        starts = [int(np.flatnonzero(rows[name])[0]) for name in SEGMENTS]
        bounds = tuple(zip(starts, [*starts[1:], path.n_points], strict=True))
        segs = {name: Segment(ell[lo:hi], tmin[lo:hi])
                for name, (lo, hi) in zip(SEGMENTS, bounds, strict=True)}
        return cls(model, moves, segs, bounds, np.asarray(ell, float), np.asarray(tmin, float),
                   dict(planned or {}))

    def times_at(self, velocities: Mapping[str, float]) -> dict[str, float]:
        """Each stretch's time at its velocity (in/s: belt travel for R I and R III, path for
        R II and R IV), as the simulation times it (:class:`cell.arm.motors.Segment`)."""
        return {name: self.segments[name].time(velocities[name]) for name in SEGMENTS}

    def move_rates(self, times_s: Mapping[str, float]) -> Array:
        """(N,) 1 / t of each move for the stretches' times; 0 on planned stretches."""
        t = np.zeros(len(self.lengths_in))
        for name, (lo, hi) in zip(SEGMENTS, self.bounds, strict=True):
            if name not in self.planned:
                v = self.segments[name].velocity(times_s[name])
                t[lo:hi] = np.maximum(self.lengths_in[lo:hi] / v, self.min_times_s[lo:hi])
        return np.divide(1.0, t, out=np.zeros_like(t), where=t > 0)

    def joint_work(self, times_s: Mapping[str, float], friction: bool = True
                   ) -> dict[str, JointWork]:
        """Per stretch, each joint's positive and negative work.  The instant change of rates at
        a point counts to the stretch of the move that leaves it (the last: to R IV)."""
        r = self.move_rates(times_s)
        within_up, within_down, jump = self.moves.work(r, friction)
        starts = [lo for lo, _ in self.bounds]
        sup = (np.add.reduceat(within_up, starts)
               + np.add.reduceat(np.maximum(jump, 0.0), [lo - 1 for lo in starts]))
        brk = (np.add.reduceat(within_down, starts)
               + np.add.reduceat(np.maximum(-jump, 0.0), [lo - 1 for lo in starts]))
        with np.errstate(divide="ignore"):
            duration = np.add.reduceat(np.where(r > 0, 1.0 / np.where(r > 0, r, 1.0), 0.0), starts)
        out = {}
        for i, name in enumerate(SEGMENTS):
            if name in self.planned:
                leg = self.planned[name].work(times_s[name], friction)
                out[name] = JointWork(sup[i] + leg.supplied, brk[i] + leg.braking,
                                      float(times_s[name]))
            else:
                out[name] = JointWork(sup[i], brk[i], float(duration[i]))
        return out

    def energy(self, work: JointWork) -> Energy:
        """Mechanical and electrical energy of some joint work (the model's drives)."""
        e = self.model.electrical
        eta = np.asarray(e.motion_efficiency, float)
        standing = float(e.standing_w().sum() * work.time_s)
        elec = standing + float(np.sum(work.supplied / eta))
        if e.recover_braking:
            elec -= float(np.sum(eta * work.braking))
        return Energy(work.time_s, float(work.net.sum()), float(work.supplied.sum()),
                      float(work.braking.sum()), standing, elec)

    def legs(self, times_s: Mapping[str, float]) -> dict[str, Energy]:
        """Each stretch's energy (:data:`cell.arm.steptable.SEGMENTS`), for its time."""
        return {name: self.energy(w) for name, w in self.joint_work(times_s).items()}

    def transfer(self, times_s: Mapping[str, float]) -> Energy:
        """One transfer, B to B, rest to rest, with each stretch taking its time."""
        work = list(self.joint_work(times_s).values())
        return self.energy(JointWork(np.sum([w.supplied for w in work], axis=0),
                                     np.sum([w.braking for w in work], axis=0),
                                     float(sum(w.time_s for w in work))))


def step_positions(table: StepTable) -> Array:
    """(N, 5) joint angles where the steppers put the joints: whole steps (rad)."""
    k = np.asarray(table.motors.steps_per_rad, float)
    return np.asarray(np.rint(table.path.q_rad * k) / k)


def planned_legs(table: StepTable, model: DynamicsModel, geometry: CellGeometry,
                 results: Mapping[str, RegimeResult]) -> dict[str, PlannedLeg]:
    """The minimum-time plans of R II and R IV (``cell.arm.mintime.regimes.plan_regimes``'s
    results) as :class:`PlannedLeg` torque terms."""
    out = {}
    for name, regime in PLANNED.items():
        res = results[regime]
        rp = regime_path(table, regime, geometry)
        ch = chain(model, geometry.arm.l2, geometry.arm.l3, rp.load_oz, rp.tcp_in)
        prof = res.profile
        out[name] = PlannedLeg.build(ch, rp.spline(), prof.s, prof.sdot, prof.time_s)
    return out
