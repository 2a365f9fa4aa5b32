"""Where everything in the cell is at an instant: pure functions, no drawing.

The animation's facts come from one run's records through :func:`frames_input` (the only
function that reads a :class:`~cell.sim.simulation.SimResult`); the rest works on the plain
arrays of :class:`AnimationInput`:

* a belt is a piecewise-constant speed history, so its travel X(t) is piecewise
  linear (§6.2 a: speed changes take effect at once): the simulation's own belt
  (:class:`cell.sim.conveyors.Belt`) replays the run's history (:func:`schedule`) and
  answers :func:`travel` and :func:`time_at`, one implementation of the rule;
* a part on the input belt is ``input_length_in`` upstream of B when the feeder
  drops it, and moves by the belt's travel; one not caught rides on and falls off
  the belt's end at F (§6.3);
* from LO to TD it is in the hand, at the tool-centre point Z T5 E (eq. 6.6);
* from TD on it moves with the output belt's travel, until it is out of view past
  the drawn output belt's end (:data:`OUTPUT_SPACINGS`, :data:`CLOSE_Y`);
* the arm follows the path's joint angles (eq. 6.7), each cycle's moves timed
  as :func:`cell.reporting.figures.motion.timeline` spreads the part's regime times (§6.1),
  and waits at B between cycles (:mod:`cell.reporting.animation.arm_pose`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cell.arm.steptable import StepTable
from cell.reporting.animation.arm_pose import ArmPose, RobotState, robot_at
from cell.reporting.animation.gate_queue import buffered, queue_x, waited_parts
from cell.reporting.animation.stops import OperatingClock
from cell.scenario.schema import Scenario
from cell.sim.conveyors import Belt

Floats = NDArray[np.float64]

#: Seconds a lost part lies, fading, at the input belt's end after it falls off at F.
FALL_S = 6.0
#: How a fallen part lies: tipped by this much (rad), just past the belt's end.
FALL_TURN_RAD = 0.4
#: Seconds shown after the last part of the window is set down (or has fallen).
TAIL_S = 2.0
#: The close-up's extent (in): the robot, both tracking windows and some belt either side.
CLOSE_X = (-36.0, 10.0)
CLOSE_Y = (-9.0, 37.0)
#: How many part spacings of output belt the strip shows past TD.
OUTPUT_SPACINGS = 2.4


@dataclass(frozen=True)
class AnimationInput:
    """One run as the animation needs it: one entry per simulated part, times in s."""

    policy: str
    part: NDArray[np.int64]
    """Part numbers 1..n."""
    arrival_s: Floats
    """The feeder drops the part on the input belt, ``input_length_in`` upstream of B."""
    at_bot_s: Floats
    """The part reaches B."""
    picked: NDArray[np.bool_]
    """Caught by the robot (else it fell off at F)."""
    start_s: Floats
    """The robot starts the part's cycle at B (NaN if not picked)."""
    pick_s: Floats
    """Lift-off, LO."""
    touchdown_s: Floats
    """Touch-down, TD."""
    regime_s: Floats
    """(n, 4) time of R I .. R IV of the part's cycle (NaN if not picked)."""
    input_belt: Floats
    """(m, 2) rows (from_s, speed_in_s) of the input belt: each speed holds until the next."""
    output_belt: Floats
    """(k, 2) the same for the output belt."""
    input_length_in: float
    """Feeder drop point to B."""
    cycle_s: float
    """The cycle the robot plans for: a non-adaptive robot's fixed cycle (the run's ideal_cycle_s)."""
    buffer_wait_s: Floats | None = None
    """(n,) how long each part stood at the buffer's gate or behind it (parts.csv's
    ``buffer_wait_s``; None: no ``buffer:``, every part moving as in the thesis's cell)."""
    pitch_in: float = 0.0
    """The buffer's pitch: centre to centre of the parts waiting in it (docs/layout.md; 0:
    no buffer)."""
    station: str = ""
    """A station of a line after the first: its name and placement (``next, series``; empty:
    the cell the feeder feeds).  Its parts are those that came to it, in the order they came,
    ``arrival_s`` the instant each was dropped on its input window (docs/layout.md)."""


def belt_history(result: Any, belt: str) -> Floats:
    """(m, 2) rows (from_s, speed_in_s) of one belt's speed changes, as the run recorded
    them (``SimResult.belts``, the rows of ``belts.csv``), in time order."""
    return np.array(result.belts[belt], dtype=float).reshape(-1, 2)


def frames_input(result: Any, scenario: Scenario) -> AnimationInput:
    """The run's part records and belt changes as plain arrays.

    ``start_s`` is ``at_bot_s`` for a picked part (the robot starts its cycle the
    moment the part reaches B); each regime's time is the record's ``rN_s``; the
    belts' speeds are the run's recorded changes (:func:`belt_history`); the drop
    point is the cell's ``input_length``.
    """
    from cell.sim.policy_setup import constants
    from cell.sim.timing_cache import robot_timing

    d = result.parts
    picked = d["picked"].to_numpy(dtype=bool)
    at_bot = d["at_bot_s"].to_numpy(dtype=float)
    return AnimationInput(
        policy=str(result.summary.policy),
        part=d["part"].to_numpy(dtype=np.int64),
        arrival_s=d["arrival_s"].to_numpy(dtype=float),
        at_bot_s=at_bot,
        picked=picked,
        start_s=np.where(picked, at_bot, np.nan),
        pick_s=d["pick_s"].to_numpy(dtype=float),
        touchdown_s=d["touchdown_s"].to_numpy(dtype=float),
        regime_s=np.where(picked[:, None],
                          d[[f"r{r}_s" for r in (1, 2, 3, 4)]].to_numpy(dtype=float), np.nan),
        input_belt=belt_history(result, "input"),
        output_belt=belt_history(result, "output"),
        input_length_in=float(constants(scenario, robot_timing(scenario)).input_length),
        cycle_s=float(result.summary.ideal_cycle_s),
        **buffered(d, scenario))


def station_input(name: str, own: Any, visits: dict[str, np.ndarray],
                  belts: dict[str, np.ndarray], waited: np.ndarray) -> AnimationInput:
    """A line's station as the animation needs it (parts.csv's row of a part is its last
    station's): the parts that came to it and what it did with each
    (:meth:`cell.sim.line.StationLog.visit_table`), its own belts, its own cell's drop point
    (``own``: its assembled cell), cycle and buffer (``waited``: each part's wait at it);
    ``name`` empty for the first station, else ``name, placement``."""
    picked = visits["picked"] == 1.0
    b = own.scenario.buffer
    buffer: dict[str, Any] = {} if b is None or not b.places else {
        "buffer_wait_s": waited, "pitch_in": float(b.pitch_in if b.pitch_in is not None
                                                   else own.scenario.part.size_in)}
    at_bot = visits["at_bot"]
    return AnimationInput(
        policy=own.policy.name, part=visits["part"].astype(np.int64) + 1,
        arrival_s=visits["arrival"], at_bot_s=at_bot, picked=picked,
        start_s=np.where(picked, at_bot, np.nan), pick_s=visits["pick"],
        touchdown_s=np.where(picked, visits["touchdown"], np.nan),
        regime_s=np.column_stack([visits[f"r{r}"] for r in (1, 2, 3, 4)]),
        input_belt=belts["input"], output_belt=belts["output"],
        input_length_in=float(own.k.input_length), cycle_s=float(own.policy.ideal_cycle_s),
        station=name, **buffer)


# --------------------------------------------------------------------------- belts
def schedule(history: ArrayLike) -> Belt:
    """The simulation's belt replaying a sorted speed history (:meth:`Belt.of_history`)."""
    return Belt.of_history(np.asarray(history, dtype=float).reshape(-1, 2).tolist())


def travel(belt: Belt | ArrayLike, t: ArrayLike) -> Floats:
    """X(t), inches ``belt`` (a :func:`schedule`, or its history: rows (from_s, speed_in_s),
    sorted; the last speed holds for ever, the first is extrapolated back) has moved since its
    first change, at each t of any shape (:meth:`cell.sim.conveyors.Belt.travel`)."""
    b = belt if isinstance(belt, Belt) else schedule(belt)
    with np.errstate(all="ignore"):  # NaN in (a part never picked): NaN out
        return np.vectorize(b.travel, otypes=[float])(np.asarray(t, dtype=float))


def time_at(belt: Belt | ArrayLike, x: ArrayLike) -> Floats:
    """The instant the belt's travel reaches each x (:meth:`cell.sim.conveyors.Belt.time_at`,
    the inverse of :func:`travel`; inf where the belt stands from its last change on)."""
    b = belt if isinstance(belt, Belt) else schedule(belt)
    with np.errstate(all="ignore"):
        return np.vectorize(b.time_at, otypes=[float])(np.asarray(x, dtype=float))


# --------------------------------------------------------------------------- the scene
@dataclass(frozen=True)
class Scene:
    """A run, the cell's geometry and the robot's timed cycles, ready to ask "where, when"."""

    data: AnimationInput
    table: StepTable
    scenario: Scenario
    cycle_part: NDArray[np.int64]
    """(c,) index (0-based) of the part each robot cycle carries."""
    cycle_t_s: Floats
    """(c, N) instant the robot reaches each path point in each cycle."""
    fall_s: Floats
    """(n,) instant a part not caught reaches the belt's end at F (NaN if picked)."""
    arrival_travel_in: Floats
    """(n,) the input belt's travel X at each part's drop."""
    touchdown_travel_in: Floats
    """(n,) the output belt's travel at each part's TD (NaN if not picked)."""
    off_output_s: Floats
    """(n,) instant a part set down is out of view, a part's size past the output belt's
    drawn end (:func:`output_gone_y`); it leaves the scene then (NaN if not picked)."""
    stops: tuple[tuple[str, str, float, float], ...] = ()
    """(equipment, cause, from_s, to_s) of every stop of the run: a failure, a worn motor, a
    planned stop (failures.csv's rows)."""

    @cached_property
    def input_belt(self) -> Belt:
        """The input belt's schedule (:func:`schedule` of the run's history)."""
        return schedule(self.data.input_belt)

    @cached_property
    def output_belt(self) -> Belt:
        """The output belt's schedule."""
        return schedule(self.data.output_belt)

    @cached_property
    def clock(self) -> OperatingClock:
        """The robot's operating clock: its moves' time, its stops taken out."""
        return OperatingClock.of(self.stops)

    def stopped_at(self, t: float) -> dict[str, tuple[str, float]]:
        """The equipment stopped at instant t: name -> (cause, seconds until it is back)."""
        return {name: (cause, end - t) for name, cause, start, end in self.stops
                if start <= t < end}

    @property
    def b_xy(self) -> Floats:
        return np.asarray(self.scenario.path.bot_in[:2], dtype=float)

    @property
    def f_xy(self) -> Floats:
        return np.asarray(self.scenario.path.f_in[:2], dtype=float)

    @property
    def td_xy(self) -> Floats:
        return self.table.path.xyz_in[self.table.path.td, :2]

    @property
    def output_end_y(self) -> float:
        return output_end_y(self.scenario, self.table)


def output_end_y(scenario: Scenario, table: StepTable) -> float:
    """Where the output belt's strip ends (y, in): :data:`OUTPUT_SPACINGS` spacings past TD."""
    return float(table.path.xyz_in[table.path.td, 1] + OUTPUT_SPACINGS * scenario.belts.spacing_in)


def output_gone_y(scenario: Scenario, table: StepTable) -> float:
    """A part's centre past this y (in) is drawn nowhere: a part's size past the farther
    of the output strip's end and the close-up's top."""
    return max(output_end_y(scenario, table), CLOSE_Y[1]) + scenario.part.size_in


def build_scene(data: AnimationInput, table: StepTable, scenario: Scenario,
                from_s: float = -math.inf,
                stops: tuple[tuple[str, str, float, float], ...] = ()) -> Scene:
    """Time the robot's cycles move by move (``timeline``, §6.1), find each lost part's fall
    and when each part set down has left the drawn output belt.

    ``from_s``: the scene is asked about instants from then on, so the cycles that end
    before it are not timed (``--from-part`` deep into a long run times a few cycles, not
    every one before them)."""
    from cell.reporting.figures.motion import record_segments, timeline

    clock = OperatingClock.of(stops)  # the regime times leave the robot's stops out
    start, pick, td = (clock.operating(v) for v in (data.start_s, data.pick_s, data.touchdown_s))
    ends = clock.wall(start + np.nansum(data.regime_s, axis=1))
    cycles = np.flatnonzero(data.picked & (ends >= from_s))
    t_s = np.empty((len(cycles), table.path.n_points))
    for row, i in enumerate(cycles):
        seg = record_segments(start[i], pick[i], td[i], data.regime_s[i])
        t_s[row] = clock.wall(start[i] + timeline(table, seg).t_s)
    to_f = data.input_length_in + float(scenario.path.f_in[0] - scenario.path.bot_in[0])
    belt_in, belt_out = schedule(data.input_belt), schedule(data.output_belt)
    x_drop = travel(belt_in, data.arrival_s)
    fall = np.where(data.picked, np.nan, time_at(belt_in, x_drop + to_f))
    waited = waited_parts(data)
    if waited.any():  # let go at the gate (at_bot_s): from B on with the belt
        x_b = travel(belt_in, data.at_bot_s[waited])
        to_f_b = float(scenario.path.f_in[0] - scenario.path.bot_in[0])
        fall[waited] = np.where(data.picked[waited], np.nan, time_at(belt_in, x_b + to_f_b))
    y_td = np.where(data.picked, travel(belt_out, data.touchdown_s), np.nan)
    to_gone = output_gone_y(scenario, table) - float(table.path.xyz_in[table.path.td, 1])
    off = np.where(data.picked, time_at(belt_out, y_td + to_gone), np.nan)
    return Scene(data, table, scenario, cycles.astype(np.int64), t_s, fall, x_drop, y_td, off,
                 tuple(stops))


# --------------------------------------------------------------------------- the parts
#: Where a part is: not on the belt yet (or gone), input belt, hand, output belt, or fallen
#: off the input belt's end (lying tipped just past F for FALL_S, fading, then gone).
ABSENT, INPUT, HAND, OUTPUT, FALLING = 0, 1, 2, 3, 4


@dataclass(frozen=True)
class PartsAt:
    """Every part at one instant."""

    where: NDArray[np.int64]
    """(n,) ABSENT, INPUT, HAND, OUTPUT or FALLING."""
    xy: Floats
    """(n, 2) centre on the table (NaN when absent)."""
    angle_rad: Floats
    """(n,) turn about z (the part turns 90° in R II)."""
    alpha: Floats
    """(n,) opacity: 1, fading to 0 over FALL_S once it has fallen."""


def parts_at(scene: Scene, t: float, robot: tuple[RobotState, ArmPose] | None = None) -> PartsAt:
    """Every part's place at instant t (see the module's docstring).

    ``robot``: :func:`robot_at` of the same instant, if the caller has it already (a
    part in the hand is where the tool centre is); else it is worked out when needed.
    """
    d = scene.data
    n = len(d.part)
    xy = np.full((n, 2), np.nan)
    angle = np.zeros(n)
    alpha = np.ones(n)
    where = np.full(n, ABSENT, dtype=np.int64)
    with np.errstate(invalid="ignore"):
        dropped = d.arrival_s <= t
        gone_by = np.where(d.picked, d.pick_s, scene.fall_s + FALL_S)
        on_input = dropped & (t < gone_by)
        falling = on_input & ~d.picked & (t >= scene.fall_s)
        held = d.picked & (d.pick_s <= t) & (t < d.touchdown_s)
        out = d.picked & (t >= d.touchdown_s) & (t < scene.off_output_s)
    x_in = scene.b_xy[0] - d.input_length_in + (travel(scene.input_belt, t) - scene.arrival_travel_in)
    waited = waited_parts(d)
    if waited.any():  # a buffer: parts queued at the gate, and those it let go
        queued, x_q = queue_x(scene, t, x_in)
        x_in = np.where(queued, x_q, x_in)
        gone = waited & ~queued & (d.at_bot_s <= t)
        x_in = np.where(gone, scene.b_xy[0] + travel(scene.input_belt, t)
                        - travel(scene.input_belt, d.at_bot_s), x_in)
    xy[on_input] = np.column_stack([x_in, np.full(n, scene.b_xy[1])])[on_input]
    where[on_input] = INPUT
    where[falling] = FALLING
    xy[falling] = scene.f_xy + [scene.scenario.part.size_in / 2, 0.0]
    angle[falling] = FALL_TURN_RAD
    alpha[falling] = np.clip(1.0 - (t - scene.fall_s[falling]) / FALL_S, 0.0, 1.0)
    if held.any():
        state, pose = robot if robot is not None else robot_at(scene, t)
        xy[held] = pose.tcp[0, :2]
        angle[held] = state.phi_rad[0]
        where[held] = HAND
    y_out = scene.td_xy[1] + travel(scene.output_belt, t) - scene.touchdown_travel_in
    xy[out] = np.column_stack([np.full(n, scene.td_xy[0]), y_out])[out]
    angle[out] = scene.table.path.phi_rad[scene.table.path.td]
    where[out] = OUTPUT
    return PartsAt(where, xy, angle, alpha)


def shown_between(scene: Scene, t0: float, t1: float) -> NDArray[np.int64]:
    """Indices of the parts that are somewhere in the scene at some instant of [t0, t1]
    (dropped by t1, and not yet gone, off the output belt or faded after a fall, at t0)."""
    d = scene.data
    gone = np.where(d.picked, scene.off_output_s, scene.fall_s + FALL_S)
    with np.errstate(invalid="ignore"):
        return np.flatnonzero((d.arrival_s <= t1) & ~(gone < t0))


@dataclass(frozen=True)
class Counts:
    arrived: int
    delivered: int
    lost: int


def counts_at(scene: Scene, t: float) -> Counts:
    """Parts dropped, set down and fallen off by t, since the run began."""
    d = scene.data
    with np.errstate(invalid="ignore"):
        return Counts(int(np.sum(d.arrival_s <= t)), int(np.sum(d.touchdown_s <= t)),
                      int(np.sum(scene.fall_s <= t)))


# --------------------------------------------------------------------------- the window
def part_done_s(scene: Scene, index: int) -> float:
    """When part ``index`` (0-based) leaves the story: set down, or faded after its fall."""
    d = scene.data
    return float(d.touchdown_s[index] if d.picked[index] else scene.fall_s[index] + FALL_S)


def window(scenes: list[Scene], first: int, count: int) -> tuple[float, float]:
    """From part ``first``'s arrival (1-based) to the set-down or fall of part
    ``first + count - 1`` in whichever run is later, plus :data:`TAIL_S`; a line's stations
    after the first: until each has done with every part up to it that came to it."""
    t0 = float(scenes[0].data.arrival_s[first - 1])
    t1 = max(part_done_s(s, first + count - 2) for s in scenes if not s.data.station)
    for s in scenes:
        if s.data.station:
            came = np.flatnonzero(s.data.part <= first + count - 1)
            t1 = max([t1, *(part_done_s(s, int(i)) for i in came)])
    return t0, t1 + TAIL_S


def frame_times(t0: float, t1: float, step_s: float) -> Floats:
    """Instants of the frames: every ``step_s`` from t0, the last at or before t1."""
    n = math.floor((t1 - t0) / step_s + 1e-9) + 1
    return (t0 + step_s * np.arange(n)).astype(np.float64)
