"""The robot of an animation's scene at instants: its joints and its arm's pose.

In a cycle the joints move linearly in time between the path's points, as
:func:`cell.reporting.animation.scene.build_scene` timed them (eq. 6.7); between cycles the
robot waits at B, and while it is stopped (``failures:``, ``wear:``) the arm stands still.
The arm's pose is the forward kinematics of those joints.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cell.arm.kinematics import Arm, forward, hand_frame
from cell.scenario.schema import Scenario

if TYPE_CHECKING:
    from cell.reporting.animation.scene import Floats, Scene


@dataclass(frozen=True)
class RobotState:
    """The robot at instants t (leading dimension T)."""

    q_rad: Floats
    """(T, 5) joint angles, interpolated between path points by time."""
    opening_in: Floats
    """(T,) finger opening G (eq. 6.2)."""
    phi_rad: Floats
    """(T,) the held part's turn about z (eq. 6.3-6.5)."""
    regime: NDArray[np.int64]
    """(T,) 1..4, or 0 waiting at B."""
    part: NDArray[np.int64]
    """(T,) index of the part of the current cycle, -1 waiting."""


def robot_state(scene: Scene, t: ArrayLike) -> RobotState:
    """Where the joints are at each t: in a cycle, linear in time between path points."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    p = scene.table.path
    values = np.column_stack([p.q_rad, p.opening_in, p.phi_rad])  # (N, 7)
    out = np.tile(values[0], (len(t), 1))
    regime = np.zeros(len(t), dtype=np.int64)
    part = np.full(len(t), -1, dtype=np.int64)
    times, clock = scene.cycle_t_s, scene.clock
    if len(times):
        k = np.searchsorted(times[:, 0], t, side="right") - 1
        active = (k >= 0) & (t <= times[np.maximum(k, 0), -1])
        for c in np.unique(k[active]):
            sel = active & (k == c)
            tc = t[sel]
            run, at = clock.operating(tc), clock.operating(times[c])  # still while stopped
            out[sel] = np.column_stack([np.interp(run, at, values[:, j])
                                        for j in range(values.shape[1])])
            move = np.clip(np.searchsorted(times[c], tc, side="left"), 1, p.n_points - 1)
            regime[sel] = p.regime[move]
            part[sel] = scene.cycle_part[c]
    return RobotState(out[:, :5], out[:, 5], out[:, 6], regime, part)


@dataclass(frozen=True)
class ArmPose:
    """The arm projected on the table (global frame, inches), leading dimension T."""

    joints: Floats
    """(T, 4, 3) base axis on the table, elbow, wrist, tool-centre point."""
    fingers: Floats
    """(T, 2, 3) the two finger tips: tool centre ± G/2 along the hand's o axis."""

    @property
    def tcp(self) -> Floats:
        return self.joints[:, 3]


def arm_pose(scenario: Scenario, q_rad: ArrayLike, opening_in: ArrayLike) -> ArmPose:
    """Forward kinematics Z A1 ... A5 E (eq. 3.13, 6.1, 6.2, 6.6) of the arm's joints.

    The shoulder is on the base axis; the elbow is the origin of A1 A2 (the same
    chain with no forearm); the wrist is T5's origin (a4 = a5 = d = 0, Table 3.1).
    """
    q = np.atleast_2d(np.asarray(q_rad, dtype=float))
    g = np.atleast_1d(np.asarray(opening_in, dtype=float))
    from cell.sim.scenario_values import geometry_of

    geometry = geometry_of(scenario)
    arm = geometry.arm
    z = geometry.placement.frame()
    wrist_frame = z @ forward(q, arm)
    elbow = (z @ forward(q * [1, 1, 0, 0, 0], Arm(arm.l2, 0.0, arm.limits)))[:, :3, 3]
    tool = wrist_frame @ hand_frame(g, geometry.hand)
    base = np.broadcast_to(np.asarray(scenario.cell.robot_base_in, dtype=float), elbow.shape)
    joints = np.stack([base, elbow, wrist_frame[:, :3, 3], tool[:, :3, 3]], axis=1)
    half = 0.5 * g[:, None] * tool[:, :3, 1]
    fingers = np.stack([tool[:, :3, 3] - half, tool[:, :3, 3] + half], axis=1)
    return ArmPose(joints, fingers)


def robot_at(scene: Scene, t: float) -> tuple[RobotState, ArmPose]:
    """The robot's joints and its arm's pose at one instant (leading dimension 1)."""
    state = robot_state(scene, t)
    return state, arm_pose(scene.scenario, state.q_rad, state.opening_in)
