"""One transfer in time: Fig. 15-21 (thesis §7.1).

The path is timed at its nominal regime velocities (``docs/model.md``, "The
nominal cycle"): R I and R III locked to their belts (each move takes its
advance along the belt over the belt speed), R IV at the base's nominal rate and
R II the rest of the 22.5872 s ideal cycle.  No move is ever shorter than its
motors allow (§6.1): after LO the loaded shoulder cannot quite keep up with the
3 in/s belt (§4.3 c), so R I takes 2.729 s rather than 8/3 s and R II 5.867 s
rather than the thesis's 5.935 s, as in the simulation.

Each regime's time is the simulation's; the figures spread it over the moves on
the joints' travel (:func:`joint_travel_min_times`), what the motors do, rather
than on the whole steps the simulation counts, whose 10- and 11-step moves would
make the rates flicker by a step per move.  Fig. 22 draws one simulated transfer
the same way.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cell.arm.kinematics import JOINT_NAMES
from cell.arm.motors import max_rates, min_move_times, move_times, velocity_for_time
from cell.arm.steptable import SEGMENTS, StepTable
from cell.reporting.figures.style import (
    LIMIT_COLOUR,
    REGIME_LABELS,
    mark_events,
    new_figure,
    save,
    shade_regimes,
)
from cell.scenario.schema import Scenario


@dataclass(frozen=True)
class Timeline:
    """A transfer timed move by move."""

    t_s: NDArray[np.float64]
    """(N,) time at each path point, 0 at B."""
    dt_s: NDArray[np.float64]
    """(N,) duration of the move arriving at each point (row 0: 0)."""
    segment_s: dict[str, float]
    """Duration of each of :data:`SEGMENTS`."""

    @property
    def regime_s(self) -> dict[int, float]:
        g = self.segment_s
        return {1: g["r1_pre"] + g["r1_post"], 2: g["r2"], 3: g["r3_pre"] + g["r3_post"],
                4: g["r4"]}


def record_segments(start_s: float, pick_s: float, touchdown_s: float,
                    regime_s: ArrayLike) -> dict[str, float]:
    """A simulated cycle's six stretches (:data:`~cell.arm.steptable.SEGMENTS`) from its
    records: each regime's time, R I and R III split at LO and TD (§4.2)."""
    r1, r2, r3, r4 = (float(v) for v in np.asarray(regime_s, dtype=float))
    r1_pre = pick_s - start_s
    r3_pre = touchdown_s - start_s - r1 - r2
    seg = {"r1_pre": r1_pre, "r1_post": r1 - r1_pre, "r2": r2, "r3_pre": r3_pre,
           "r3_post": r3 - r3_pre, "r4": r4}
    return {k: seg[k] for k in SEGMENTS}


def joint_travel_min_times(table: StepTable) -> NDArray[np.float64]:
    """(N,) each move's shortest time over the joints' travel |Δθ|·k at their peak rates
    (§6.1), without rounding each path point to whole steps (row 0: 0).

    The simulation times a move by its whole steps, round(θ·k) at each point, so a
    motor at its limit alternates moves of, say, 10 and 11 steps over equal lengths;
    a whole regime's steps add up to its travel either way.
    """
    k = np.asarray(table.motors.steps_per_rad, dtype=float)
    travel = np.vstack([np.zeros((1, 5)), np.diff(table.path.q_rad, axis=0) * k])
    return min_move_times(travel, table.path.load_oz, table.motors)


def spread(lengths: NDArray[np.float64], floors: NDArray[np.float64],
           total_s: float) -> NDArray[np.float64]:
    """Each move's time when ``total_s`` is spread over moves of these lengths: one
    velocity v for all, every move max(ℓ/v, t_min) (§6.1).

    At or below the floors' sum every move runs at its floor, scaled to ``total_s``;
    a stretch with no length (v undefined) shares its time in proportion to the floors.
    """
    fsum = float(floors.sum())
    if total_s <= fsum or not np.any(lengths > 0):
        if fsum > 0:
            return floors * (total_s / fsum)
        return np.full(len(floors), total_s / max(len(floors), 1))
    return move_times(lengths, floors, velocity_for_time(lengths, floors, total_s))


def timeline(table: StepTable, segment_s: dict[str, float],
             floors: NDArray[np.float64] | None = None) -> Timeline:
    """Spread each segment's time over its moves (:func:`spread`).

    ``floors``: each move's shortest time; the simulation's whole-step ones
    (``table.peak_min_times``) unless given, e.g. :func:`joint_travel_min_times`.
    Each segment then lasts exactly its given time.
    """
    ell = table.velocity_lengths
    floor = table.peak_min_times if floors is None else np.asarray(floors, dtype=float)
    dt = np.zeros(table.path.n_points)
    for name, rows in table.segment_rows().items():
        dt[rows] = spread(ell[rows], floor[rows], float(segment_s[name]))
    return Timeline(np.cumsum(dt), dt, {k: float(segment_s[k]) for k in SEGMENTS})


def nominal_timeline(table: StepTable, s: Scenario,
                     floors: NDArray[np.float64] | None = None) -> Timeline:
    """One transfer at the nominal velocities, as the controllers plan it (``docs/model.md``):
    R I and R III locked to their belts at nominal speed, R IV at the nominal (75 %)
    motor rates, and R II the rest of the ideal cycle (the thesis's
    22.5872 - 8/3 - 4 - 9.9855 = 5.935 s if R I took exactly 8/3 s).  ``floors`` as
    in :func:`timeline`."""
    from cell.sim.policy_setup import constants
    from cell.sim.timing_cache import robot_timing

    k = constants(s, robot_timing(s))
    return timeline(table, {"r1_pre": k.r1_pre_nom, "r1_post": k.r1_post_nom, "r2": k.r2_nom,
                            "r3_pre": k.r3_pre_nom, "r3_post": k.r3_post_nom, "r4": k.r4_nom},
                    floors)


def _events(table: StepTable, tl: Timeline) -> dict[str, float]:
    return {"LO": float(tl.t_s[table.path.lo]), "TD": float(tl.t_s[table.path.td])}


def _regime_note(tl: Timeline) -> str:
    parts = ", ".join(f"{REGIME_LABELS[r]} {tl.regime_s[r]:.3f} s" for r in (1, 2, 3, 4))
    return f"one transfer at nominal velocities: {parts}; cycle {tl.t_s[-1]:.3f} s"


def fig15_coordinates(table: StepTable, tl: Timeline, out: Path) -> Path:
    fig, ax = new_figure(15, "Change in Coordinates wrt Time")
    p = table.path
    shade_regimes(ax, tl.t_s, p.regime)
    for j, (name, col) in enumerate(zip("xyz", ("#1f77b4", "#ff7f0e", "#2ca02c"), strict=True)):
        ax.plot(tl.t_s, p.xyz_in[:, j], color=col, label=f"{name} (tool centre, global frame)")
    mark_events(ax, _events(table, tl))
    ax.set_xlabel("time from B (s)")
    ax.set_ylabel("coordinate (in)")
    ax.set_xlim(0, tl.t_s[-1])
    ax.legend(loc="upper left", fontsize=8.5)
    ax.set_title(_regime_note(tl), loc="left", fontsize=9, pad=16)
    return save(fig, out)


def fig16_joint_angles(table: StepTable, tl: Timeline, out: Path) -> Path:
    fig, ax = new_figure(16, "Change in Joint Angles wrt Time")
    p = table.path
    shade_regimes(ax, tl.t_s, p.regime)
    deg = np.degrees(p.q_rad)
    for j in range(5):
        ax.plot(tl.t_s, deg[:, j], label=f"θ{j + 1} {JOINT_NAMES[j]}")
    mark_events(ax, _events(table, tl))
    ax.set_xlabel("time from B (s)")
    ax.set_ylabel("joint angle (deg, DH convention)")
    ax.set_xlim(0, tl.t_s[-1])
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=8.5)
    ax.set_title(_regime_note(tl), loc="left", fontsize=9, pad=16)
    return save(fig, out)


def fig_joint_rate(table: StepTable, tl: Timeline, steps_tl: Timeline, s: Scenario, joint: int,
                   out: Path) -> Path:
    """Fig. 17-21: joint ``joint`` (0..4) rate in steps/s with its maximum rates (§6.1).

    Black: the joint's travel over each move's time on the joints' travel (``tl``,
    :func:`joint_travel_min_times`), what the motor does; grey: the whole steps the
    simulation counts over its whole-step move times (``steps_tl``).  Neither exceeds
    the maximum rate.
    """
    p = table.path
    number = 17 + joint
    fig, ax = new_figure(number, f"Theta {joint + 1} Joint Rates")
    shade_regimes(ax, tl.t_s, p.regime)
    with np.errstate(invalid="ignore", divide="ignore"):
        rate = np.where(steps_tl.dt_s[1:] > 0, table.steps[1:, joint] / steps_tl.dt_s[1:], 0.0)
    peak = max_rates(p.load_oz[1:], table.motors, 1.0)[:, joint]
    nominal = peak * s.robot.motors.nominal_fraction
    ax.stairs(peak, tl.t_s, baseline=None, color=LIMIT_COLOUR, lw=1.3,
              label="maximum rate (100 %, at the move's load)")
    ax.stairs(-peak, tl.t_s, baseline=None, color=LIMIT_COLOUR, lw=1.3)
    ax.stairs(nominal, tl.t_s, baseline=None, color=LIMIT_COLOUR, lw=1.0, ls="--",
              label=f"nominal rate ({s.robot.motors.nominal_fraction:.0%})")
    ax.stairs(-nominal, tl.t_s, baseline=None, color=LIMIT_COLOUR, lw=1.0, ls="--")
    k = s.robot.motors.steps_per_rad[joint]
    with np.errstate(invalid="ignore", divide="ignore"):
        smooth = np.where(tl.dt_s[1:] > 0, np.diff(p.q_rad[:, joint]) * k / tl.dt_s[1:], 0.0)
    ax.stairs(rate, steps_tl.t_s, baseline=None, color="0.55", lw=0.8,
              label="whole motor steps per move / move time on whole steps")
    ax.stairs(smooth, tl.t_s, baseline=None, color="black", lw=1.5,
              label=f"θ{joint + 1} ({JOINT_NAMES[joint]}) rate, dθ/dt × {k:g} steps/rad")
    ax.axhline(0, color="0.5", lw=0.6)
    mark_events(ax, _events(table, tl))
    ax.set_xlabel("time from B (s)")
    ax.set_ylabel("joint rate (motor steps/s)")
    ax.set_xlim(0, tl.t_s[-1])
    top = max(float(np.max(np.abs(rate))), float(peak.max()))
    ax.set_ylim(-1.08 * top, 1.08 * top)
    fig.legend(loc="outside lower center", fontsize=8.5, ncols=2)
    ax.set_title(f"{k:g} steps/rad; peak |dθ/dt| {np.max(np.abs(smooth)):.0f} steps/s",
                 loc="left", fontsize=9, pad=16)
    return save(fig, out)
