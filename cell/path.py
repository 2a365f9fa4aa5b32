"""The transfer path B → F → G → K → B (thesis §4.2, Fig. 9; SPEC §3).

Four regimes:

* R I   B → F: track the input belt's centreline; dip to the pick height at LO.
* R II  F → G: arc about the base axis at constant height; the part turns 90°.
* R III G → K: track the output belt; dip to the place height at TD.
* R IV  K → B: arc back; the empty hand turns back to its R I orientation.

The straight parts are divided equally along the belt (x on the input belt, y on
the output belt); the height changes are clamped cubic splines (the thesis's
Fowler-Wilson routine; ``scipy.interpolate.CubicSpline(bc_type="clamped")``);
the arcs are divided equally in base angle.  Point 0 is B; the last point is B
again, so the default 459 moves give 460 points.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from cell.errors import ScenarioError, UnreachableError
from cell.kinematics import Arm, arm_target, inverse_kinematics
from cell.scenario import Scenario

REGIMES = ("R1", "R2", "R3", "R4")


@dataclass(frozen=True)
class TransferPath:
    """Points of one transfer cycle and what the hand does at each.

    Arrays have one entry per point; per-move quantities (``regime``,
    ``load_oz``) belong to the move that *arrives* at the point.
    """

    xyz_in: NDArray[np.float64]
    """(N, 3) tool-centre points, global frame."""
    regime: NDArray[np.int64]
    """(N,) 1..4: regime of the move arriving at the point (point 0: 1)."""
    phi_rad: NDArray[np.float64]
    """(N,) part rotation about z: 0 in R I, 90° in R III (eq. 6.3, 6.5)."""
    opening_in: NDArray[np.float64]
    """(N,) finger opening G (eq. 6.2)."""
    load_oz: NDArray[np.float64]
    """(N,) load carried during the move arriving at the point."""
    q_rad: NDArray[np.float64]
    """(N, 5) joint angles from eq. 6.7 and the inverse kinematics."""
    lo: int
    """Index of lift-off (pick-up)."""
    td: int
    """Index of touch-down (release)."""

    @property
    def n_points(self) -> int:
        return len(self.regime)

    @property
    def events(self) -> NDArray[np.str_]:
        ev = np.full(self.n_points, "", dtype="<U2")
        ev[self.lo], ev[self.td] = "LO", "TD"
        return ev

    @property
    def move_in(self) -> NDArray[np.float64]:
        """(N,) straight-line length of the move arriving at each point (0 for point 0)."""
        return np.concatenate([[0.0], np.linalg.norm(np.diff(self.xyz_in, axis=0), axis=1)])


def _dip(start: NDArray, end: NDArray, dip_from_start: float, low_z: float,
         n_moves: int) -> tuple[NDArray, int]:
    """Points of a straight tracking segment with a spline dip to ``low_z``.

    Returns (n_moves + 1, 3) points and the index of the dip's bottom.  The
    stretch start → dip and dip → end are each divided equally; the height is a
    clamped cubic spline through (start, dip, end).
    """
    length = float(np.linalg.norm(end - start))
    n_down = int(np.clip(round(n_moves * dip_from_start / length), 1, n_moves - 1))
    s = np.concatenate([np.linspace(0.0, dip_from_start, n_down + 1),
                        np.linspace(dip_from_start, length, n_moves - n_down + 1)[1:]])
    xy = start[:2] + np.outer(s / length, end[:2] - start[:2])
    spline = CubicSpline([0.0, dip_from_start, length], [start[2], low_z, end[2]],
                         bc_type="clamped")
    return np.column_stack([xy, spline(s)]), n_down


def _arc(start: NDArray, end: NDArray, centre_xy: NDArray, yaw: float,
         n_moves: int) -> NDArray:
    """Points of an arc about the base axis, equal steps in base angle.

    Angles are measured in the robot frame so the arc never leaves the base's
    range (R IV from K to B goes through the robot's x axis, not behind it).
    """
    def polar(p: NDArray) -> tuple[float, float]:
        d = p[:2] - centre_xy
        ang = np.arctan2(d[1], d[0]) - yaw
        return float(np.hypot(*d)), float(np.arctan2(np.sin(ang), np.cos(ang)))

    (r0, a0), (r1, a1) = polar(start), polar(end)
    f = np.linspace(0.0, 1.0, n_moves + 1)
    ang = a0 + f * (a1 - a0) + yaw
    rad = r0 + f * (r1 - r0)
    z = start[2] + f * (end[2] - start[2])
    return np.column_stack([centre_xy[0] + rad * np.cos(ang), centre_xy[1] + rad * np.sin(ang), z])


def build_path(s: Scenario) -> TransferPath:
    """The path of scenario ``s`` with its joint angles (eq. 6.7 at every point).

    Raises :class:`ScenarioError` naming the scenario key nearest the first
    point that is out of reach or needs a joint outside its range.
    """
    p = s.path
    m = p.moves
    b, f, g, k = (np.asarray(v, dtype=float) for v in (p.bot_in, p.f_in, p.g_in, p.eot_in))
    centre = np.asarray(s.cell.robot_base_in[:2], dtype=float)
    yaw = np.radians(s.cell.robot_yaw_deg)

    r1, lo_local = _dip(b, f, p.lo_from_bot_in, p.pick_height_in, m.R1)
    r2 = _arc(f, g, centre, yaw, m.R2)
    r3, td_local = _dip(g, k, p.td_from_g_in, p.place_height_in, m.R3)
    r4 = _arc(k, b, centre, yaw, m.R4)
    xyz = np.vstack([r1, r2[1:], r3[1:], r4[1:]])
    regime = np.concatenate([np.full(m.R1 + 1, 1), np.full(m.R2, 2), np.full(m.R3, 3),
                             np.full(m.R4, 4)])
    lo = lo_local
    g_idx = m.R1 + m.R2
    td = g_idx + td_local
    quarter = np.pi / 2
    phi = np.concatenate([np.zeros(m.R1 + 1), np.linspace(0, quarter, m.R2 + 1)[1:],
                          np.full(m.R3, quarter), np.linspace(quarter, 0, m.R4 + 1)[1:]])
    idx = np.arange(len(regime))
    holding = (idx >= lo) & (idx <= td)
    opening = np.where(holding, s.part.size_in, s.robot.hand.open_in)
    load = np.where((idx > lo) & (idx <= td), s.part.weight_oz, 0.0)

    labels = [f"path point {i} ({REGIMES[regime[i] - 1]}) at "
              f"({xyz[i, 0]:.3f}, {xyz[i, 1]:.3f}, {xyz[i, 2]:.3f})" for i in range(len(idx))]
    try:
        q = inverse_kinematics(arm_target(xyz, phi, opening, s), Arm.from_scenario(s),
                               labels=labels)
    except UnreachableError as exc:
        i = exc.index
        key, value = _blame(s, i, regime[i], xyz[i])
        raise ScenarioError(s.source, key, value, str(exc)) from None
    return TransferPath(xyz, regime, phi, opening, load, q, lo, td)


def _blame(s: Scenario, i: int, regime: int, point: NDArray) -> tuple[str, object]:
    """The scenario key whose point lies nearest an unreachable path point."""
    p = s.path
    lo_xyz = _along(p.bot_in, p.f_in, p.lo_from_bot_in, p.pick_height_in)
    td_xyz = _along(p.g_in, p.eot_in, p.td_from_g_in, p.place_height_in)
    candidates = {
        1: [("path.bot_in", p.bot_in), ("path.f_in", p.f_in),
            ("path.pick_height_in", lo_xyz)],
        2: [("path.f_in", p.f_in), ("path.g_in", p.g_in)],
        3: [("path.g_in", p.g_in), ("path.eot_in", p.eot_in),
            ("path.place_height_in", td_xyz)],
        4: [("path.eot_in", p.eot_in), ("path.bot_in", p.bot_in)],
    }[int(regime)]
    key, _ = min(candidates,
                     key=lambda kv: float(np.linalg.norm(np.subtract(kv[1], point))))
    value = s.get(key)
    return key, list(value) if isinstance(value, tuple) else value


def _along(start: tuple, end: tuple, distance: float, z: float) -> NDArray:
    a, b = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    xy = a[:2] + (b[:2] - a[:2]) * distance / np.linalg.norm(b - a)
    return np.array([xy[0], xy[1], z])
