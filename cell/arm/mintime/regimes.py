"""The planner on the cell's freely moving regimes, R II and R IV (thesis §4.2).

Each regime's joint path q(s) is the step table's joint angles at its points
(s = 0 … 1, one equal step per move: the arcs are equal chords in base angle),
through a cubic spline for q' and q''.  The bounds (:class:`PlannerBounds`):

* joint velocity: the motors' step rates at the regime's load (§6.1,
  ``cell.arm.motors.max_rates``) times ``rate_fraction``;
* joint acceleration: ``qddot_max_rad_s2`` (if given);
* joint torque: a rigid-body model (if given), each drive on its torque-speed
  line (``cell.arm.dynamics``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from cell.arm.dynamics import DynamicsModel, chain, free_speed
from cell.arm.kinematics import JOINT_NAMES, hand_length
from cell.arm.motors import Motors, max_rates
from cell.arm.path import CellGeometry
from cell.arm.steptable import StepTable
from cell.plumbing.cache import memo
from cell.plumbing.errors import CellError, NoMotionError

from .planner import PathRows, Profile, acceleration_rows, path_grid, plan, torque_rows, velocity_rows

FREE_REGIMES = ("R2", "R4")


@dataclass(frozen=True)
class PlannerBounds:
    """What limits the motion along the path (Shin & McKay 1983)."""

    grid_points: int = 460
    """Grid points per regime, s scaled to [0, 1]."""
    rate_fraction: float = 1.0
    """Joint velocity bounds = the motors' step rates at the load times this."""
    qddot_max_rad_s2: tuple[float, ...] = (2.0, 2.0, 4.0, 8.0, 8.0)
    """Joint acceleration bounds (rad/s²)."""
    acceleration_bounds: bool = True
    """Whether ``qddot_max_rad_s2`` applies."""
    dynamics: DynamicsModel | None = None
    """The rigid-body model for torque bounds, or None for none."""


@dataclass(frozen=True)
class RegimePath:
    """One regime's joint path and what the hand carries."""

    regime: str
    s_way: NDArray[np.float64]
    q_way: NDArray[np.float64]
    load_oz: float
    tcp_in: float
    """Hand length to the tool centre (eq. 6.2) during the regime."""

    def spline(self) -> CubicSpline:
        return CubicSpline(self.s_way, self.q_way, bc_type="not-a-knot")


def regime_path(table: StepTable, regime: str, geometry: CellGeometry) -> RegimePath:
    pts = table.regime_points(regime)
    moves = pts[1:]
    q = table.path.q_rad[pts]
    load = float(table.path.load_oz[moves].max())
    tcp = float(np.asarray(hand_length(table.path.opening_in[moves[0]], geometry.hand)))
    return RegimePath(regime, np.linspace(0.0, 1.0, len(pts)), q, load, tcp)


def regime_rows(rp: RegimePath, motors: Motors, bounds: PlannerBounds, geometry: CellGeometry,
                n_grid: int | None = None,
                ) -> tuple[NDArray[np.float64], NDArray[np.float64], PathRows, NDArray[np.float64]]:
    """(grid s, q(s), the rows of every bound, the joint velocity bounds) for one regime."""
    n = n_grid or bounds.grid_points
    s = path_grid(n)
    sp = rp.spline()
    q, dq, ddq = sp(s), sp(s, 1), sp(s, 2)
    vmax = (max_rates(rp.load_oz, motors, bounds.rate_fraction)
            / np.asarray(motors.steps_per_rad, float))
    parts = [velocity_rows(s, dq, vmax)]
    amax = np.asarray(bounds.qddot_max_rad_s2, float) if bounds.acceleration_bounds else None
    if amax is not None:
        parts.append(acceleration_rows(s, dq, ddq, amax))
    model = bounds.dynamics
    if model is not None:
        ch = chain(model, geometry.arm.l2, geometry.arm.l3, rp.load_oz, rp.tcp_in)
        tau_s = np.asarray(model.drives.stall_torque_nm, float)
        w_f = free_speed(model, motors.max_rate_no_load_rad_s)
        parts.append(torque_rows(s, q, dq, ddq, ch.rnea, tau_s, viscous=ch.viscous,
                                 line_slope=tau_s / w_f))
    if amax is None and model is None:
        raise NoMotionError("no acceleration or torque bounds: the fastest motion would need "
                            "infinite acceleration")
    return s, q, PathRows.join(*parts), vmax


@dataclass(frozen=True)
class Shortfall:
    """Joint ``joint`` (0-4) needs ``needed_nm`` to hold the arm still at ``s`` of ``regime``,
    more than its stall torque ``stall_nm`` (shown rounded up, so that the value shown holds)."""

    regime: str
    s: float
    joint: int
    needed_nm: float
    stall_nm: float

    def text(self, first: bool = True) -> str:
        """The shortfall in words; after the first, shorter (the line stays readable)."""
        s, name = self.s, f"the {JOINT_NAMES[self.joint]} (joint {self.joint + 1})"
        needed, stall = f"{_rounded_up(self.needed_nm):.3g} N·m", f"{self.stall_nm:.3g} N·m"
        if not first:
            return f"{name} {needed} (s = {s:.4f} of {self.regime}), more than its {stall}"
        where = "at the start of" if s == 0 else "at the end of" if s == 1 else f"at s = {s:.4f} of"
        return (f"{name} needs {needed} to hold the arm against gravity {where} {self.regime}, "
                f"more than its stall torque {stall}")


def _rounded_up(x: float) -> float:
    """``x`` rounded up at three significant digits: a stall torque set to it holds."""
    scale = 10.0 ** (2 - math.floor(math.log10(x))) if x > 0 else 1.0
    return math.ceil(x * scale) / scale


class WeakDriveError(NoMotionError):
    """No motion where a drive cannot hold the arm against gravity at rest: one
    :class:`Shortfall` per joint that falls short, each at the point that needs the most."""

    def __init__(self, shortfalls: tuple[Shortfall, ...]):
        self.shortfalls = shortfalls
        super().__init__("; ".join(f.text(i == 0) for i, f in enumerate(shortfalls)))

    def blame(self, model: DynamicsModel, reference: DynamicsModel, name: str
              ) -> tuple[str, Any, str]:
        """(key, value, words to add) for a dynamics file: the first of :data:`HOLDING_KEYS`
        in which ``model`` differs from ``reference`` (file ``name``), the others named in
        the words; the stall torques only if lower at a joint that falls short (a stronger
        drive is no cause), and by default."""
        ours, theirs = model.drives.stall_torque_nm, reference.drives.stall_torque_nm
        lower = any(ours[f.joint] < theirs[f.joint] for f in self.shortfalls)
        changed = [k for k in HOLDING_KEYS if model_value(model, k) != model_value(reference, k)
                   and (k != "drives.stall_torque_nm" or lower)] or ["drives.stall_torque_nm"]
        verb = "differs" if len(changed) == 2 else "differ"
        also = f"; {' and '.join(changed[1:])} {verb} from the built-in {name} too" \
            if len(changed) > 1 else ""
        return changed[0], model_value(model, changed[0]), also


#: A dynamics file's keys that holding the arm against gravity depends on, in the order blame
#: is given.
HOLDING_KEYS = ("drives.stall_torque_nm", "links.mass_kg", "links.com_m", "gravity_m_s2")


def model_value(model: DynamicsModel, key: str) -> Any:
    """The value of a dynamics file's dotted ``key`` in ``model``, tuples as the file's lists."""
    value: Any = model
    for part in key.split("."):
        value = getattr(value, part)
    return _listed(value)


def _listed(value: Any) -> Any:
    return [_listed(v) for v in value] if isinstance(value, tuple) else value


def weak_drive(table: StepTable, model: DynamicsModel | None, geometry: CellGeometry,
               n_grid: int) -> WeakDriveError | None:
    """The drives whose stall torque cannot hold the arm still (gravity alone) somewhere on
    the free regimes' grids, or None.  Each joint is named with the most any grid point of any
    regime needs: a stall torque raised to that holds the arm everywhere."""
    if model is None:
        return None
    stall = np.asarray(model.drives.stall_torque_nm, float)
    s = path_grid(n_grid)
    worst: dict[int, Shortfall] = {}
    for r in FREE_REGIMES:
        rp = regime_path(table, r, geometry)
        ch = chain(model, geometry.arm.l2, geometry.arm.l3, rp.load_oz, rp.tcp_in)
        q = rp.spline()(s)
        zero = np.zeros_like(q)
        hold = np.abs(ch.rnea(q, zero, zero, friction=False, gravity=True))
        for j in np.flatnonzero((hold > stall).any(axis=0)):
            i = int(np.argmax(hold[:, j]))
            if int(j) not in worst or hold[i, j] > worst[int(j)].needed_nm:
                worst[int(j)] = Shortfall(r, float(s[i]), int(j), float(hold[i, j]), float(stall[j]))
    return WeakDriveError(tuple(worst[j] for j in sorted(worst))) if worst else None


@dataclass(frozen=True)
class RegimeResult:
    regime: str
    q: NDArray[np.float64]
    profile: Profile
    qdot_max_rad_s: NDArray[np.float64]
    """The joint velocity bounds used (rad/s)."""


def plan_regimes(geometry: CellGeometry, motors: Motors, bounds: PlannerBounds,
                 n_grid: int | None = None) -> dict[str, RegimeResult]:
    """The minimum-time profile of R II and R IV, rest to rest."""
    table = StepTable.solve(geometry, motors)
    out = {}
    for r in FREE_REGIMES:
        rp = regime_path(table, r, geometry)
        s, q, rows, vmax = regime_rows(rp, motors, bounds, geometry, n_grid)
        try:
            profile = plan(rows)
        except CellError as exc:
            weak = weak_drive(table, bounds.dynamics, geometry, len(s))
            raise weak or NoMotionError(f"regime {r}: {exc}") from None
        out[r] = RegimeResult(r, q, profile, vmax)
    return out


@memo(maxsize=16)
def fastest_regime_times(geometry: CellGeometry, motors: Motors, bounds: PlannerBounds
                         ) -> dict[str, float]:
    """{"R2": s, "R4": s}: the minimum-time traversal of each free regime, rest to rest
    (cached on what it depends on, so a simulation calls the planner once)."""
    res = plan_regimes(geometry, motors, bounds)
    return {r: res[r].profile.time_s for r in FREE_REGIMES}


def summary(results: dict[str, RegimeResult], bounds: PlannerBounds) -> dict[str, Any]:
    """The FILE.json content of ``cell mintime``.

    ``limits.qdot_max_rad_s`` is the elementwise tightest over the regimes (R II
    carries the part, so its rates are lower); each regime also lists its own.
    ``limits.qddot_max_rad_s2`` is there only when the acceleration bounds applied.
    """
    v = np.min([res.qdot_max_rad_s for res in results.values()], axis=0)
    limits: dict[str, Any] = {"qdot_max_rad_s": v.tolist()}
    if bounds.acceleration_bounds:
        limits["qddot_max_rad_s2"] = list(bounds.qddot_max_rad_s2)
    limits["acceleration_bounds"] = bounds.acceleration_bounds
    limits["torque"] = bounds.dynamics is not None
    return {
        "regimes": {r: {"time_s": res.profile.time_s, "switching_s": res.profile.switching_s,
                        "qdot_max_rad_s": res.qdot_max_rad_s.tolist(),
                        "grid_points": len(res.profile.s)}
                    for r, res in results.items()},
        "limits": limits,
    }
