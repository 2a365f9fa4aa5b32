"""The planner on the cell's freely moving regimes, R II and R IV (thesis §4.2).

Each regime's joint path q(s) is the step table's joint angles at its points
(s = 0 … 1, one equal step per move: the arcs are equal chords in base angle),
through a cubic spline for q' and q''.  The bounds:

* joint velocity: the motors' step rates at the regime's load (§6.1,
  ``cell.motors.max_rates``) times ``mintime.rate_fraction``;
* joint acceleration: ``mintime.qddot_max_rad_s2`` (if ``acceleration_bounds``);
* joint torque: the rigid-body model of ``mintime.dynamics_file`` (if set), each
  drive on its torque-speed line (``cell.dynamics``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from cell.errors import CellError, ScenarioError
from cell.motors import max_rates
from cell.scenario import Scenario, to_dict
from cell.steptable import StepTable

from .planner import PathRows, Profile, acceleration_rows, plan, torque_rows, velocity_rows

FREE_REGIMES = ("R2", "R4")


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


def regime_path(table: StepTable, regime: str, scenario: Scenario) -> RegimePath:
    from cell.kinematics import hand_length

    moves = np.flatnonzero(table.regime_rows(regime))
    pts = np.arange(moves[0] - 1, moves[-1] + 1)
    q = table.path.q_rad[pts]
    load = float(table.path.load_oz[moves].max())
    tcp = float(np.asarray(hand_length(table.path.opening_in[moves[0]], scenario)))
    return RegimePath(regime, np.linspace(0.0, 1.0, len(pts)), q, load, tcp)


@dataclass(frozen=True)
class Limits:
    qdot_max_rad_s: NDArray[np.float64]
    qddot_max_rad_s2: NDArray[np.float64] | None
    torque: bool


def regime_rows(scenario: Scenario, rp: RegimePath, n_grid: int | None = None,
                ) -> tuple[NDArray[np.float64], NDArray[np.float64], PathRows, Limits]:
    """(grid s, q(s), the rows of every bound, the limits used) for one regime."""
    mt = scenario.mintime
    motors = scenario.robot.motors
    n = n_grid or mt.grid_points
    s = np.linspace(0.0, 1.0, n)
    sp = rp.spline()
    q, dq, ddq = sp(s), sp(s, 1), sp(s, 2)
    vmax = (max_rates(rp.load_oz, motors, mt.rate_fraction)
            / np.asarray(motors.steps_per_rad, float))
    parts = [velocity_rows(s, dq, vmax)]
    amax = np.asarray(mt.qddot_max_rad_s2, float) if mt.acceleration_bounds else None
    if amax is not None:
        parts.append(acceleration_rows(s, dq, ddq, amax))
    torque = mt.dynamics_file is not None
    if torque:
        from cell.dynamics import chain, free_speed, load_dynamics

        path = scenario.base_dir / mt.dynamics_file
        if not path.is_file():
            raise ScenarioError(scenario.source, "mintime.dynamics_file", mt.dynamics_file,
                                f"no such file (looked for {path})")
        model = load_dynamics(path, scenario.source)
        ch = chain(model, scenario.robot.l2_in, scenario.robot.l3_in, rp.load_oz, rp.tcp_in)
        tau_s = np.asarray(model.drives.stall_torque_nm, float)
        w_f = free_speed(model, motors.max_rate_no_load_rad_s)
        parts.append(torque_rows(s, q, dq, ddq, ch.rnea, tau_s, viscous=ch.viscous,
                                 line_slope=tau_s / w_f))
    if amax is None and not torque:
        raise CellError(f"{scenario.source}: mintime: no acceleration or torque bounds "
                        "(mintime.acceleration_bounds is false and mintime.dynamics_file "
                        "is empty): the fastest motion would need infinite acceleration")
    return s, q, PathRows.join(*parts), Limits(vmax, amax, torque)


@dataclass(frozen=True)
class RegimeResult:
    regime: str
    q: NDArray[np.float64]
    profile: Profile
    limits: Limits


def plan_regimes(scenario: Scenario, table: StepTable | None = None,
                 n_grid: int | None = None) -> dict[str, RegimeResult]:
    """The minimum-time profile of R II and R IV, rest to rest."""
    table = table or StepTable.from_scenario(scenario)
    out = {}
    for r in FREE_REGIMES:
        rp = regime_path(table, r, scenario)
        s, q, rows, limits = regime_rows(scenario, rp, n_grid)
        try:
            profile = plan(rows)
        except CellError as exc:
            raise CellError(f"{scenario.source}: regime {r}: {exc}") from None
        out[r] = RegimeResult(r, q, profile, limits)
    return out


_CACHE: dict[str, dict[str, float]] = {}


def _key(scenario: Scenario) -> str:
    d = to_dict(scenario)
    keep = {k: d[k] for k in ("cell", "path", "part", "robot", "mintime")}
    keep["robot"] = {k: v for k, v in keep["robot"].items() if k != "timing"}
    return json.dumps([str(scenario.base_dir.resolve()), keep], sort_keys=True, default=str)


def fastest_regime_times(scenario: Scenario, table: StepTable | None = None) -> dict[str, float]:
    """{"R2": s, "R4": s}: the minimum-time traversal of each free regime, rest to rest.

    Cached per scenario (only the settings that change the answer count), so a
    simulation calls the planner once, not per part.  ``table``: the scenario's
    solved path, if the caller has it (saves solving it again).
    """
    key = _key(scenario)
    if key not in _CACHE:
        res = plan_regimes(scenario, table)
        _CACHE[key] = {r: res[r].profile.time_s for r in FREE_REGIMES}
    return dict(_CACHE[key])


def summary(results: dict[str, RegimeResult], scenario: Scenario) -> dict[str, Any]:
    """The FILE.json content of ``cell mintime``.

    ``limits.qdot_max_rad_s`` is the elementwise tightest over the regimes (R II
    carries the part, so its rates are lower); each regime also lists its own.
    """
    v = np.min([res.limits.qdot_max_rad_s for res in results.values()], axis=0)
    mt = scenario.mintime
    return {
        "regimes": {r: {"time_s": res.profile.time_s, "switching_s": res.profile.switching_s,
                        "qdot_max_rad_s": res.limits.qdot_max_rad_s.tolist(),
                        "grid_points": len(res.profile.s)}
                    for r, res in results.items()},
        "limits": {
            "qdot_max_rad_s": v.tolist(),
            "qddot_max_rad_s2": list(mt.qddot_max_rad_s2),
            "acceleration_bounds": mt.acceleration_bounds,
            "torque": mt.dynamics_file is not None,
        },
    }
