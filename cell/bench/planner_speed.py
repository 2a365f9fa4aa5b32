"""Planner speed against toppra on the transfer path, and the planner's accuracy
(merged into reports/bench.json by ``cell bench``).

Speed: the joint paths of R II and R IV from the step table, their peak velocity
bounds and the acceleration bounds of ``scenarios/mintime_kinematic.yaml`` (velocity +
acceleration: toppra's fastest, Cython, case).  Both planners start from the same
waypoints, build their own spline and constraints on the same grid
(``path_grid(n)``), and return ṡ on it; the time of the best of several runs, in ms.
The torque case (baseline dynamic model, 460 points) is reported beside it.

Accuracy: ``mintime_r4_dynamic_rel_err`` is R IV under the baseline's dynamic model on
its default grid against the converged time, from the planner on 460·2^k points
(k = 0 … 4) extrapolated at second order (Richardson).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from cell.plumbing.stopwatch import best_seconds

if TYPE_CHECKING:
    from cell.arm.mintime.regimes import PlannerBounds, RegimePath
    from cell.arm.motors import Motors
    from cell.arm.path import CellGeometry
    from cell.scenario.schema import Scenario

RICHARDSON = tuple(460 * 2 ** k for k in range(5))


def converged_time(times: list[float]) -> float:
    """T∞ from times on doubling grids: the last plus a third of the last change (second order)."""
    return times[-1] + (times[-1] - times[-2]) / 3.0


def regime_time(rp: RegimePath, motors: Motors, bounds: PlannerBounds, geometry: CellGeometry,
                n: int | None = None) -> float:
    """One regime's minimum time (s) on n grid points (None: the bounds' own), planned alone:
    what :func:`~cell.arm.mintime.regimes.plan_regimes` gives for it, without the other regime."""
    from cell.arm.mintime.planner import plan
    from cell.arm.mintime.regimes import regime_rows

    return plan(regime_rows(rp, motors, bounds, geometry, n)[2]).time_s


def _kinematic_speed(repeat: int) -> tuple[list[RegimePath], dict[str, np.ndarray], dict[str, float]]:
    """The velocity + acceleration case against toppra on 460 and 2000 points: the free
    regimes' paths, their peak velocity bounds and the timings (ms) and relative time gaps."""
    from cell.arm.mintime.planner import path_grid
    from cell.arm.mintime.reference import toppra_profile
    from cell.arm.mintime.regimes import FREE_REGIMES, regime_path, regime_rows
    from cell.scenario.schema import load_scenario
    from cell.sim.physics_checks import step_table
    from cell.sim.scenario_values import geometry_of, motors_of, planner_bounds

    kin = load_scenario("mintime_kinematic")
    table = step_table(kin)
    geometry, motors, bounds = geometry_of(kin), motors_of(kin), planner_bounds(kin)
    paths = [regime_path(table, r, geometry) for r in FREE_REGIMES]
    amax = np.asarray(kin.mintime.qddot_max_rad_s2)
    vmax = {rp.regime: regime_rows(rp, motors, bounds, geometry, 3)[3] for rp in paths}

    def ours(n: int) -> list[float]:
        return [regime_time(rp, motors, bounds, geometry, n) for rp in paths]

    def theirs(n: int) -> list[float]:
        s = path_grid(n)
        return [toppra_profile(rp.s_way, rp.q_way, s, qdot_max=vmax[rp.regime], qddot_max=amax)[1]
                for rp in paths]

    out: dict[str, float] = {}
    for n in (460, 2000):
        a, b = ours(n), theirs(n)
        out[f"mintime_ms_{n}"] = 1e3 * best_seconds(lambda: ours(n), repeat)       # noqa: B023
        out[f"toppra_ms_{n}"] = 1e3 * best_seconds(lambda: theirs(n), repeat)      # noqa: B023
        out[f"mintime_vs_toppra_time_rel_{n}"] = float(max(abs(x - y) / y for x, y in zip(a, b)))
    return paths, vmax, out


def _torque_speed(base: Scenario, paths: list[RegimePath],
                  vmax: dict[str, np.ndarray]) -> dict[str, float]:
    """Torque (baseline dynamic model) on R IV at 460 points: toppra calls the same inverse
    dynamics once per grid point and coefficient, the planner batches it."""
    from cell.arm.dynamics import chain
    from cell.arm.mintime.planner import PathRows, path_grid, plan, torque_rows, velocity_rows
    from cell.arm.mintime.reference import toppra_profile
    from cell.sim.scenario_values import planner_bounds

    model = planner_bounds(base).dynamics
    assert model is not None, "scenarios/baseline.yaml names a dynamics file"
    r4 = next(rp for rp in paths if rp.regime == "R4")
    ch = chain(model, base.robot.l2_in, base.robot.l3_in, r4.load_oz, r4.tcp_in)
    tau = np.asarray(model.drives.stall_torque_nm)
    s = path_grid(460)

    def ours_tau() -> float:
        sp = r4.spline()
        q, dq, ddq = sp(s), sp(s, 1), sp(s, 2)
        return plan(PathRows.join(velocity_rows(s, dq, vmax["R4"]),
                                  torque_rows(s, q, dq, ddq, ch.rnea, tau))).time_s

    def theirs_tau() -> float:
        return toppra_profile(r4.s_way, r4.q_way, s, qdot_max=vmax["R4"],
                              inv_dyn=lambda q, qd, qdd: ch.rnea(q, qd, qdd, friction=False),
                              tau_max=tau)[1]

    return {"mintime_torque_ms_460": 1e3 * best_seconds(ours_tau, 3),
            "toppra_torque_ms_460": 1e3 * best_seconds(theirs_tau, 1)}


def _r4_dynamic_rel_err(base: Scenario) -> float:
    """R IV under the baseline's dynamic model on its default grid against the converged
    (Richardson) time."""
    from cell.arm.mintime.regimes import regime_path
    from cell.sim.physics_checks import step_table
    from cell.sim.scenario_values import geometry_of, motors_of, planner_bounds

    base_geometry, base_motors, base_bounds = geometry_of(base), motors_of(base), planner_bounds(base)
    base_r4 = regime_path(step_table(base), "R4", base_geometry)
    r4_times = [regime_time(base_r4, base_motors, base_bounds, base_geometry, n) for n in RICHARDSON]
    default = regime_time(base_r4, base_motors, base_bounds, base_geometry)
    t_inf = converged_time(r4_times)
    return abs(default - t_inf) / t_inf


def benchmarks(repeat: int = 5) -> dict[str, float]:
    """Speed against toppra (kinematic and torque cases) and R IV's accuracy (module docstring)."""
    from cell.scenario.schema import load_scenario

    paths, vmax, out = _kinematic_speed(repeat)
    base = load_scenario("baseline")
    out.update(_torque_speed(base, paths, vmax))
    out["mintime_r4_dynamic_rel_err"] = _r4_dynamic_rel_err(base)
    return {k: round(v, 3) if "ms" in k else v for k, v in out.items()}


if __name__ == "__main__":  # pragma: no cover
    import json

    print(json.dumps(benchmarks(), indent=2))
