"""MICROBOT kinematics (thesis §3, §6.1; corrections in docs/model.md).

Forward kinematics is the product of the Denavit-Hartenberg A matrices
(eq. 3.1-3.7, Table 3.1), vectorised over any number of configurations.  The
inverse is the closed form of docs/model.md (the scan's eq. 3.26-3.31 are garbled).
The cell's placement Z (eq. 6.1), the hand E (eq. 6.2), the part P and grasp PG
(eq. 6.3-6.5) give the arm's target T5 = Z⁻¹ P PG E⁻¹ (eq. 6.7).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cell.arm.transforms import Frame, inverse, rot, trans
from cell.plumbing.errors import UnreachableError

JOINTS = ("theta1", "theta2", "theta3", "theta4", "theta5")
JOINT_NAMES = ("base", "shoulder", "elbow", "wrist pitch", "wrist roll")

#: Twist α and whether the link length a is L2/L3, per link (Table 3.1); d = 0 for all.
DH_ALPHA = np.radians([90.0, 0.0, 0.0, -90.0, 0.0])

#: Round-off allowed at a joint limit (rad): near the stretched-elbow singularity
#: the closed form recovers angles only to about √eps.  Not a clamp.
LIMIT_TOL_RAD = 1e-7


@dataclass(frozen=True)
class Arm:
    """The arm's geometry: link lengths (in) and joint ranges (radians, Table 3.1)."""

    l2: float = 7.0
    l3: float = 7.0
    limits: tuple[tuple[float, float], ...] = tuple(
        (float(lo), float(hi)) for lo, hi in np.radians(
            [[-90.0, 90.0], [-35.0, 144.0], [-149.0, 0.0], [-180.0, 0.0], [-180.0, 180.0]]))
    """(5, 2) lower and upper bounds in the DH convention of docs/model.md."""

    @property
    def limits_rad(self) -> NDArray[np.float64]:
        return np.asarray(self.limits, dtype=float)

    @property
    def link_a(self) -> NDArray[np.float64]:
        return np.array([0.0, self.l2, self.l3, 0.0, 0.0])


@dataclass(frozen=True)
class Hand:
    """The hand of eq. 6.2: w11 = L1 + √(L2² − (G − G0)²/2) at finger opening G (in)."""

    l1: float = 1.884
    l2: float = 1.700
    g0: float = 1.520
    open_in: float = 2.5
    """Finger opening with no part (assumed)."""


@dataclass(frozen=True)
class Placement:
    """Where the robot stands: Z = Trans(base + shoulder height) · Rot(z, yaw) (eq. 6.1)."""

    base_in: tuple[float, float, float] = (-8.0, 8.0, 0.0)
    shoulder_height_in: float = 7.68
    yaw_rad: float = float(np.radians(-45.0))

    def frame(self) -> Frame:
        bx, by, bz = self.base_in
        return trans(bx, by, bz + self.shoulder_height_in) @ rot("z", self.yaw_rad)


def a_matrix(theta: ArrayLike, d: float, a: float, alpha: float) -> Frame:
    """A = Rot(z, θ) Trans(0, 0, d) Trans(a, 0, 0) Rot(x, α) (eq. 3.1-3.2)."""
    theta = np.asarray(theta, dtype=float)
    c, s = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(alpha), np.sin(alpha)
    out = np.zeros(theta.shape + (4, 4))
    out[..., 0, :] = np.stack([c, -s * ca, s * sa, a * c], axis=-1)
    out[..., 1, :] = np.stack([s, c * ca, -c * sa, a * s], axis=-1)
    out[..., 2, 1], out[..., 2, 2], out[..., 2, 3] = sa, ca, d
    out[..., 3, 3] = 1.0
    return out


def forward(q: ArrayLike, arm: Arm = Arm()) -> Frame:
    """T5 = A1 A2 A3 A4 A5 (eq. 3.13-3.15) for configurations ``q`` of shape (..., 5)."""
    q = np.asarray(q, dtype=float)
    link_a = arm.link_a
    t = a_matrix(q[..., 0], 0.0, 0.0, DH_ALPHA[0])
    for i in range(1, 5):
        t = t @ a_matrix(q[..., i], 0.0, link_a[i], DH_ALPHA[i])
    return t


def _wrap_from(angle: NDArray[np.float64], lo: float) -> NDArray[np.float64]:
    """Angle brought into [lo, lo + 2π)."""
    return lo + np.mod(angle - lo, 2 * np.pi)


_Branch = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_], NDArray[np.bool_]]


def _ik_branch(th1: NDArray[np.float64], t: NDArray[np.float64], arm: Arm) -> _Branch:
    """One θ1 branch of the closed-form solution for frames t (N, 4, 4): the joint
    angles q (N, 5), the radial reach r, which poses are out of reach and which
    joints fall outside Table 3.1's ranges."""
    n, o, a, p = t[:, :3, 0], t[:, :3, 1], t[:, :3, 2], t[:, :3, 3]
    z = p[:, 2]
    lim = arm.limits_rad
    c1, s1 = np.cos(th1), np.sin(th1)
    th234 = np.arctan2(-(c1 * a[:, 0] + s1 * a[:, 1]), a[:, 2])
    th5 = np.arctan2(c1 * n[:, 1] - s1 * n[:, 0], c1 * o[:, 1] - s1 * o[:, 0])
    r = c1 * p[:, 0] + s1 * p[:, 1]
    c3 = (r**2 + z**2 - arm.l2**2 - arm.l3**2) / (2 * arm.l2 * arm.l3)
    reach_bad = np.abs(c3) > 1.0 + 1e-12
    c3 = np.clip(c3, -1.0, 1.0)
    s3 = -np.sqrt(1.0 - c3**2)
    th3 = np.arctan2(s3, c3)
    k1 = arm.l2 + arm.l3 * c3
    th2 = np.arctan2(k1 * z - arm.l3 * s3 * r, k1 * r + arm.l3 * s3 * z)
    th4 = th234 - th2 - th3
    q = np.stack([th1, th2, th3, th4, th5], axis=-1)
    q[:, 3] = _wrap_from(q[:, 3], lim[3, 0] - LIMIT_TOL_RAD)
    q[:, 4] = _wrap_from(q[:, 4], lim[4, 0] - LIMIT_TOL_RAD)
    outside = (q < lim[:, 0] - LIMIT_TOL_RAD) | (q > lim[:, 1] + LIMIT_TOL_RAD)
    return q, r, reach_bad, outside


def _pose_name(p: NDArray[np.float64], i: int, label: Callable[[int], str] | None) -> str:
    """How an error names pose i: ``label(i)`` if given, else its wrist position."""
    if label is not None:
        return label(i)
    return "pose at p = (" + ", ".join(f"{v:.4f}" for v in p[i]) + ") in the robot frame"


def _check_reach(r: NDArray[np.float64], z: NDArray[np.float64], reach_bad: NDArray[np.bool_],
                 arm: Arm, name: Callable[[int], str]) -> None:
    """Raise :class:`UnreachableError` for the first pose out of reach (|C3| > 1)."""
    if reach_bad.any():
        i = int(np.flatnonzero(reach_bad)[0])
        dist = float(np.hypot(r[i], z[i]))
        raise UnreachableError(
            f"{name(i)} is out of reach: the wrist would be {dist:.4f} in from the shoulder, "
            f"the arm reaches {abs(arm.l2 - arm.l3):.4f} to {arm.l2 + arm.l3:.4f} in", i, None)


def _check_ranges(q: NDArray[np.float64], outside: NDArray[np.bool_], arm: Arm,
                  name: Callable[[int], str]) -> None:
    """Raise :class:`UnreachableError` for the first joint outside its range."""
    if outside.any():
        i, j = (int(v) for v in np.argwhere(outside)[0])
        lo, hi = np.degrees(arm.limits_rad[j])
        raise UnreachableError(
            f"{name(i)} needs {JOINTS[j]} ({JOINT_NAMES[j]}) = {np.degrees(q[i, j]):.3f}°, "
            f"outside its range [{lo:g}°, {hi:g}°]", i, j)


def inverse_kinematics(t5: ArrayLike, arm: Arm = Arm(), *,
                       label: Callable[[int], str] | None = None) -> NDArray[np.float64]:
    """Joint angles (..., 5) for target frames T5 (..., 4, 4), in closed form
    (docs/sources.md: eq. 3.26-3.31 as scanned are garbled).

    The elbow-down branch (θ3 ≤ 0) of Table 3.1's ranges is taken; of θ1's two
    solutions (arm towards or away from the wrist) the one that keeps every joint
    inside its range.  A pose out of reach (|C3| > 1) or with a
    joint outside its range raises :class:`UnreachableError` naming the pose
    (``label(i)`` if given) and the joint.  Nothing is clamped.
    """
    t = np.asarray(t5, dtype=float)
    shape = t.shape[:-2]
    t = t.reshape(-1, 4, 4)
    p = t[:, :3, 3]

    def name(i: int) -> str:
        return _pose_name(p, i, label)

    # θ1 points the arm at the wrist, or away from it when the wrist sits behind the base
    # axis (θ2 > 90°): of the two, the one that keeps every joint inside its range.
    # Reach does not depend on the branch (|r| is the same), so it is checked first.
    q, r, reach_bad, outside = _ik_branch(np.arctan2(p[:, 1], p[:, 0]), t, arm)
    _check_reach(r, p[:, 2], reach_bad, arm, name)
    if outside.any():
        q_b, _, _, outside_b = _ik_branch(np.arctan2(-p[:, 1], -p[:, 0]), t, arm)
        better: NDArray[np.bool_] = np.asarray(outside.any(axis=1) & ~outside_b.any(axis=1))
        q = np.where(better[:, None], q_b, q)
        outside = np.where(better[:, None], outside_b, outside)
        _check_ranges(q, outside, arm, name)
    return q.reshape(shape + (5,))


# ----------------------------------------------------------------------------- the cell's frames
def hand_length(opening_in: ArrayLike, hand: Hand = Hand()) -> NDArray[np.float64]:
    """w11 = L1 + √(L2² - (G - G0)²/2), the hand length at finger opening G (eq. 6.2)."""
    g = np.asarray(opening_in, dtype=float)
    return hand.l1 + np.sqrt(hand.l2**2 - (g - hand.g0) ** 2 / 2)


def hand_frame(opening_in: ArrayLike, hand: Hand = Hand()) -> Frame:
    """E = Trans(0, 0, w11): the tool centre along the approach vector (eq. 6.2)."""
    w = hand_length(opening_in, hand)
    return trans(np.zeros_like(w), 0.0, w)


def part_frame(xyz_in: ArrayLike, phi_rad: ArrayLike) -> Frame:
    """P = Trans(XG, YG, ZG) · Rot(z, φ): φ = 0 in R I, 90° in R III (eq. 6.3, 6.5)."""
    xyz = np.asarray(xyz_in, dtype=float)
    return trans(xyz[..., 0], xyz[..., 1], xyz[..., 2]) @ rot("z", phi_rad)


#: PG: approach along the part's -z, orientation along its -y (eq. 6.4).
GRASP: Frame = rot("x", np.pi)


def arm_target(xyz_in: ArrayLike, phi_rad: ArrayLike, opening_in: ArrayLike,
               placement: Placement = Placement(), hand: Hand = Hand()) -> Frame:
    """T5 = Z⁻¹ P PG E⁻¹ for tool-centre points in the global frame (eq. 6.6-6.7)."""
    return inverse(placement.frame()) @ part_frame(xyz_in, phi_rad) @ GRASP @ inverse(
        hand_frame(opening_in, hand))


def tool_centre(q: ArrayLike, opening_in: ArrayLike, placement: Placement = Placement(),
                arm: Arm = Arm(), hand: Hand = Hand()) -> NDArray[np.float64]:
    """Global tool-centre point Z T5 E for joint angles q (eq. 6.6)."""
    t = placement.frame() @ forward(q, arm) @ hand_frame(opening_in, hand)
    return t[..., :3, 3]
