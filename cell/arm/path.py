"""The transfer path B → F → G → K → B (thesis §4.2, Fig. 9; docs/model.md).

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

from cell.arm.kinematics import Arm, Hand, Placement, arm_target, inverse_kinematics

REGIMES = ("R1", "R2", "R3", "R4")

Xyz = tuple[float, float, float]


@dataclass(frozen=True)
class Route:
    """The points the path runs through and how it is divided (§4.2, Fig. 9)."""

    bot_in: Xyz = (-16.0, 0.0, 3.0)
    """B: beginning of tracking on the input belt."""
    f_in: Xyz = (-8.0, 0.0, 3.0)
    """F: end of input tracking."""
    g_in: Xyz = (0.0, 8.0, 3.0)
    """G: beginning of output tracking."""
    eot_in: Xyz = (0.0, 16.0, 3.0)
    """K: end of tracking on the output belt."""
    pick_height_in: float = 1.0
    place_height_in: float = 1.0
    lo_from_bot_in: float = 4.0
    td_from_g_in: float = 4.0
    moves: tuple[int, int, int, int] = (96, 117, 96, 150)
    """Moves in R I .. R IV."""


@dataclass(frozen=True)
class CellGeometry:
    """Everything the path's shape and joint angles depend on (hashable: a cache key)."""

    route: Route = Route()
    placement: Placement = Placement()
    arm: Arm = Arm()
    hand: Hand = Hand()
    part_size_in: float = 2.0
    """The finger opening while a part is held (§6.2 f)."""
    part_weight_oz: float = 4.0
    """The load carried from LO to TD (§6.2 f)."""


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


def build_path(g: CellGeometry = CellGeometry()) -> TransferPath:
    """The path through ``g.route`` with its joint angles (eq. 6.7 at every point).

    Raises :class:`~cell.plumbing.errors.UnreachableError` for the first point out of
    reach or needing a joint outside its range; its ``index`` is that point.
    """
    p = g.route
    m1, m2, m3, m4 = p.moves
    b, f, gp, k = (np.asarray(v, dtype=float) for v in (p.bot_in, p.f_in, p.g_in, p.eot_in))
    centre = np.asarray(g.placement.base_in[:2], dtype=float)
    yaw = g.placement.yaw_rad

    r1, lo_local = _dip(b, f, p.lo_from_bot_in, p.pick_height_in, m1)
    r2 = _arc(f, gp, centre, yaw, m2)
    r3, td_local = _dip(gp, k, p.td_from_g_in, p.place_height_in, m3)
    r4 = _arc(k, b, centre, yaw, m4)
    xyz = np.vstack([r1, r2[1:], r3[1:], r4[1:]])
    regime = np.concatenate([np.full(m1 + 1, 1), np.full(m2, 2), np.full(m3, 3),
                             np.full(m4, 4)])
    lo = lo_local
    td = m1 + m2 + td_local
    quarter = np.pi / 2
    phi = np.concatenate([np.zeros(m1 + 1), np.linspace(0, quarter, m2 + 1)[1:],
                          np.full(m3, quarter), np.linspace(quarter, 0, m4 + 1)[1:]])
    idx = np.arange(len(regime))
    holding = (idx >= lo) & (idx <= td)
    opening = np.where(holding, g.part_size_in, g.hand.open_in)
    load = np.where((idx > lo) & (idx <= td), g.part_weight_oz, 0.0)

    def label(i: int) -> str:
        return (f"path point {i} ({REGIMES[regime[i] - 1]}) at "
                f"({xyz[i, 0]:.4g}, {xyz[i, 1]:.4g}, {xyz[i, 2]:.4g})")

    q = inverse_kinematics(arm_target(xyz, phi, opening, g.placement, g.hand), g.arm,
                           label=label)
    return TransferPath(xyz, regime, phi, opening, load, q, lo, td)

