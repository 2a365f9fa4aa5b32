"""One transfer in time: Fig. 15-21 (thesis §7.1).

The path is timed at its nominal regime velocities (SPEC §6): R I and R III
locked to their belts (each move takes its advance along the belt over the belt
speed), R II at the tip velocity that makes it last the nominal
22.5872 - 8/3 - 4 - 9.9855 = 5.935 s, and R IV at the base's nominal rate.
No move is ever shorter than its motors allow (§6.1): after LO the loaded
shoulder cannot quite keep up with the 3 in/s belt (§4.3 c), so R I takes a
little longer than 8/3 s.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from cell.figures.style import LIMIT_COLOUR, mark_events, new_figure, save, shade_regimes
from cell.kinematics import JOINT_NAMES
from cell.motors import max_rates, move_times, velocity_for_time
from cell.scenario import Scenario
from cell.steptable import StepTable

#: Nominal R IV time of the thesis (§5.3 step 3.2); R II gets what is left of the cycle.
R4_NOMINAL_S = 9.9855


@dataclass(frozen=True)
class Timeline:
    """A transfer timed at nominal velocities."""

    t_s: NDArray[np.float64]
    """(N,) time at each path point, 0 at B."""
    dt_s: NDArray[np.float64]
    """(N,) duration of the move arriving at each point (row 0: 0)."""
    r2_velocity_in_s: float
    regime_s: dict[int, float]
    """Duration of each regime, 1..4."""


def nominal_timeline(table: StepTable, s: Scenario) -> Timeline:
    """Time every move of one transfer at the nominal regime velocities (§6.1, SPEC §6).

    Tracking moves take (advance along the belt) / (belt speed) but never less
    than the motors' peak-rate floor; R II runs at the tip velocity that gives
    the leftover nominal time; R IV at the nominal (75 %) motor rates.
    """
    p = table.path
    along = np.concatenate([[0.0], np.linalg.norm(np.diff(p.xyz_in[:, :2], axis=0), axis=1)])
    dt = np.zeros(p.n_points)
    for reg, belt in ((1, s.belts.input_nominal_in_s), (3, s.belts.output_nominal_in_s)):
        m = table.regime_rows(reg)
        dt[m] = move_times(along[m], table.peak_min_times[m], belt)
    m4 = table.regime_rows(4)
    dt[m4] = table.nominal_min_times[m4]
    window_in = np.linalg.norm(np.subtract(s.path.f_in, s.path.bot_in))
    window_out = np.linalg.norm(np.subtract(s.path.eot_in, s.path.g_in))
    r2_time = (s.controller.nominal_cycle_s - window_in / s.belts.input_nominal_in_s
               - window_out / s.belts.output_nominal_in_s - R4_NOMINAL_S)
    m2 = table.regime_rows(2)
    v2 = velocity_for_time(table.move_in[m2], table.nominal_min_times[m2], r2_time)
    dt[m2] = move_times(table.move_in[m2], table.nominal_min_times[m2], v2)
    regime_s = {r: float(dt[table.regime_rows(r)].sum()) for r in (1, 2, 3, 4)}
    return Timeline(np.cumsum(dt), dt, v2, regime_s)


def _events(table: StepTable, tl: Timeline) -> dict[str, float]:
    return {"LO": float(tl.t_s[table.path.lo]), "TD": float(tl.t_s[table.path.td])}


def _regime_note(tl: Timeline) -> str:
    parts = ", ".join(f"R{'I' * r if r < 4 else 'IV'} {tl.regime_s[r]:.3f} s" for r in (1, 2, 3, 4))
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


def fig_joint_rate(table: StepTable, tl: Timeline, s: Scenario, joint: int, out: Path) -> Path:
    """Fig. 17-21: joint ``joint`` (0..4) rate in steps/s with its maximum rates (§6.1)."""
    p = table.path
    number = 17 + joint
    fig, ax = new_figure(number, f"Theta {joint + 1} Joint Rates")
    shade_regimes(ax, tl.t_s, p.regime)
    with np.errstate(invalid="ignore", divide="ignore"):
        rate = np.where(tl.dt_s[1:] > 0, table.steps[1:, joint] / tl.dt_s[1:], 0.0)
    peak = max_rates(p.load_oz[1:], s.robot.motors, 1.0)[:, joint]
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
    ax.stairs(rate, tl.t_s, baseline=None, color="0.55", lw=0.8,
              label="whole motor steps per move / move time")
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
    ax.set_title(f"{k:g} steps/rad; peak |rate| {np.max(np.abs(rate)):.0f} steps/s",
                 loc="left", fontsize=9, pad=16)
    return save(fig, out)

