"""The two operating policies (thesis §5.3, §6.3; SPEC §7).

The decisions are pure functions of the cell's state (:func:`adaptive_plan`,
:func:`fixed_plan`); :class:`Controller` is the thin SimPy process that reads the
state when a part reaches B, asks for a plan and hands it to the belts and the
robot.

Adaptive, one part ahead (§5.3; steps 1.0-2.1 reconstructed, SPEC §7):

1.0  the next part's distance and the belt speeds are read;
2.x  R I tracks the input belt at its current speed v; the difference from the
     nominal R I time is given to (2.1) or taken from (2.2) R II, so the cycle
     stays at the ideal 22.5872 s unless R II is already at its fastest;
3.1  next part late: after the tracking lag (B → LO) the input belt speeds up so
     that the part reaches B as the robot gets back;
3.2  next part early: the time is made up in R IV down to the base's maximum rate,
     then the input belt slows for the rest;
5.0  the output belt runs, until the robot reaches G, at the average of the
     speeds that would give 44.75 and 45.25 in spacing, then nominal;
6.2  the thesis's "time between deliveries": motion time to TD plus the previous
     cycle's residual (TD → K and R IV), idle waits not counted;
6.3  after the cycle, an input speed above nominal becomes (current + nominal)/2.

Targets are physical: the controller knows the belts' schedules, so it aims
the next part at B for the instant the robot gets back, and the spacing at 45 in,
exactly; only motor and belt limits can make it miss, and then it says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import simpy

from cell.conveyors import EPS_S, InputConveyor, OutputConveyor
from cell.errors import ScenarioError
from cell.robot import Order, Robot, RobotTiming
from cell.scenario import Scenario

#: The output belt never runs backwards; this is its crawl when asked to stop (in/s).
OUTPUT_MIN_IN_S = 0.01

#: The thesis's figures are rounded to 4 decimals: a requested R IV this much
#: below the motors' minimum is taken as the minimum (20.0907 s in Table 7.1 is
#: 0.3 ms under the 9.9855 · 0.75-based figure).
ROUNDING_S = 5e-4


@dataclass(frozen=True)
class CellConstants:
    """What the controllers know of the cell, computed once per scenario."""

    timing: RobotTiming
    v_nom: float
    """Nominal input belt speed, in/s (§5.2)."""
    u_nom: float
    """Nominal output belt speed, in/s (§5.2)."""
    cycle_nom: float
    """The ideal cycle, mean inter-arrival time (§5.3)."""
    input_max: float
    output_max: float
    spacing: float
    tol: float
    input_length: float
    """Feeder drop point to B (in)."""
    r1_pre_nom: float
    r1_post_nom: float
    r3_pre_nom: float
    r3_post_nom: float
    r4_nom: float
    r2_nom: float
    """R II's share of the ideal cycle: what the other regimes leave of it (SPEC §6)."""
    r1_nom: float
    """R I at the nominal input belt: 8/3 s at belt pace plus the motor floor after LO."""


def constants(s: Scenario, timing: RobotTiming) -> CellConstants:
    """The controllers' constants; a cell that cannot run its nominal cycle is an error."""
    b, c = s.belts, s.controller
    file = s.source
    if b.input_nominal_in_s > timing.input_track_max_in_s:
        raise ScenarioError(file, "belts.input_nominal_in_s", b.input_nominal_in_s,
                            f"the robot can follow the input belt down to LO at no more "
                            f"than {timing.input_track_max_in_s:.4f} in/s")
    if b.output_nominal_in_s > timing.output_track_max_in_s:
        raise ScenarioError(file, "belts.output_nominal_in_s", b.output_nominal_in_s,
                            f"the robot can follow the output belt down to TD at no more "
                            f"than {timing.output_track_max_in_s:.4f} in/s")
    if b.input_max_in_s < b.input_nominal_in_s:
        raise ScenarioError(file, "belts.input_max_in_s", b.input_max_in_s,
                            "must be at least belts.input_nominal_in_s")
    if b.output_max_in_s < b.output_nominal_in_s:
        raise ScenarioError(file, "belts.output_max_in_s", b.output_max_in_s,
                            "must be at least belts.output_nominal_in_s")
    t = timing
    r1a, r1b = t.r1_time(b.input_nominal_in_s)
    r3a, r3b = t.r3_time(b.output_nominal_in_s)
    r4 = max(t.r4_nominal_s, t.r4_min_s)
    r2 = c.nominal_cycle_s - r1a - r1b - r3a - r3b - r4
    if r2 < t.r2_min_s:
        raise ScenarioError(file, "controller.nominal_cycle_s", c.nominal_cycle_s,
                            f"leaves {r2:.4f} s for R II, which takes at least "
                            f"{t.r2_min_s:.4f} s at the motors' peak rates")
    length = b.input_length_in if b.input_length_in is not None else \
        b.input_nominal_in_s * c.nominal_cycle_s * 2
    return CellConstants(
        timing=t, v_nom=b.input_nominal_in_s, u_nom=b.output_nominal_in_s,
        cycle_nom=c.nominal_cycle_s, input_max=min(b.input_max_in_s, 1e9),
        output_max=b.output_max_in_s, spacing=b.spacing_in, tol=b.spacing_tol_in,
        input_length=length, r1_pre_nom=r1a, r1_post_nom=r1b, r3_pre_nom=r3a,
        r3_post_nom=r3b, r4_nom=r4, r2_nom=r2, r1_nom=r1a + r1b)


class Plan(NamedTuple):
    """One transfer cycle: regime times (s), belt speeds (in/s) and what went wrong."""

    r1_pre: float
    r1_post: float
    r2: float
    r3_pre: float
    r3_post: float
    r4: float
    input_speed: float
    """Input belt while R I tracks the part (the belt's speed when it reached B)."""
    input_after_lo: float
    """Input belt from LO until the cycle ends (steps 3.1/3.2)."""
    input_next: float
    """Input belt after the cycle (step 6.3): the next part's R I tracking speed."""
    output_to_g: float
    """Output belt until the robot reaches G (step 5.0)."""
    to_g: float
    """TTSOT counted from the start of this cycle: R I + R II (step 5.0)."""
    cycle: float
    """The robot's motion time for the whole cycle B → B."""
    note: str


def adaptive_plan(k: CellConstants, v: float, nxt: tuple[float, float] | None,
                  gap_in: float | None, lag: float | None = None) -> Plan:
    """Thesis §5.3 steps 2.0-6.3 for one part (pure).

    ``v``: input belt speed now (R I tracks it).  ``nxt = (a, b)``: the next part
    reaches B a + b/w seconds from now if the input belt runs at w from LO on
    (a = the lag B → LO and b = its pseudo-distance then, or, for a part not yet
    on the belt, a = time until the feeder drops it and b = the belt's length);
    None if no part is coming.  ``gap_in``: how far the last part set down has
    travelled on the output belt (None before the first).  ``lag``: B → LO at v,
    if the caller has it already.
    """
    t = k.timing
    notes = []
    r1a = t.r1_pre.time(v) if lag is None else lag
    r1b = t.r1_post.time(v)
    # 2.1-2.3: R I's difference from nominal goes to R II.
    r2 = k.r2_nom + (k.r1_nom - r1a - r1b)
    if r2 < t.r2_min_s:
        notes.append("R II at its fastest")
        r2 = t.r2_min_s
    r3a, r3b, r4 = k.r3_pre_nom, k.r3_post_nom, k.r4_nom
    cycle = r1a + r1b + r2 + r3a + r3b + r4
    w = v
    if nxt is not None:
        a, b = nxt
        eta = a + b / v                       # 3.0: next arrival at the current speed
        if eta > cycle:                       # 3.1: late; speed the belt up after the lag
            w = b / (cycle - a) if cycle > a else math.inf
            if w > k.input_max:
                w = k.input_max
                notes.append("input belt at its maximum: robot waits")
        elif eta < cycle:                     # 3.2: early; R IV first, then the belt
            need = cycle - eta
            if r4 - need >= t.r4_min_s:
                r4 -= need
                cycle -= need
            else:
                cycle -= r4 - t.r4_min_s
                r4 = t.r4_min_s
                w = b / (cycle - a)
    # 6.3: decay toward nominal after the cycle.
    v_next = 0.5 * (w + k.v_nom) if w > k.v_nom else w
    if v_next > t.input_track_max_in_s:
        v_next = t.input_track_max_in_s
        notes.append("input belt held to the robot's tracking limit")
    # 5.0: output belt until G, between the 44.75 and 45.25 in limits.
    u = k.u_nom
    if gap_in is not None:
        ttsot = r1a + r1b + r2
        rest = gap_in + k.u_nom * r3a
        lo = (k.spacing - k.tol - rest) / ttsot
        hi = (k.spacing + k.tol - rest) / ttsot
        u = 0.5 * (lo + hi)
        if not OUTPUT_MIN_IN_S <= u <= k.output_max:
            u = min(max(u, OUTPUT_MIN_IN_S), k.output_max)
            notes.append("output belt at its limit: spacing off")
    return Plan(r1a, r1b, r2, r3a, r3b, r4, v, w, v_next, u, r1a + r1b + r2, cycle,
                "; ".join(notes))


def fixed_plan(k: CellConstants, ideal_cycle_s: float, file: object = None) -> Plan:
    """The non-adaptive robot's one cycle (§6.3): nominal regimes, R IV shortened
    by (nominal - ideal) as in Table 7.1.  A cycle the base cannot make is an error."""
    t = k.timing
    r4 = k.r4_nom - (k.cycle_nom - ideal_cycle_s)
    if r4 < t.r4_min_s - ROUNDING_S:
        shortest = k.cycle_nom - (k.r4_nom - t.r4_min_s)
        raise ScenarioError(file, "controller.ideal_cycle_s", ideal_cycle_s,
                            f"R IV would take {r4:.4f} s but the base needs at least "
                            f"{t.r4_min_s:.4f} s at its peak rate: the shortest cycle is "
                            f"{shortest:.4f} s")
    r4 = max(r4, t.r4_min_s)
    to_g = k.r1_pre_nom + k.r1_post_nom + k.r2_nom
    return Plan(k.r1_pre_nom, k.r1_post_nom, k.r2_nom, k.r3_pre_nom, k.r3_post_nom, r4,
                k.v_nom, k.v_nom, k.v_nom, k.u_nom, to_g,
                to_g + k.r3_pre_nom + k.r3_post_nom + r4, "")


class Log:
    """Per-part facts gathered during a run (lists indexed by part number).

    The controller stores each caught part's :class:`Plan` and the thesis's step
    6.2 interval; the robot its lift-off and touch-down instants.  Columns are
    built from these once, after the run.
    """

    def __init__(self, n: int):
        nan = float("nan")
        self.at_bot_s = [nan] * n
        self.pick_s = [nan] * n
        self.touchdown_s = [nan] * n
        self.plan: list[Plan | None] = [None] * n
        self.thesis_interval_s = [nan] * n
        """Step 6.2: motion time to TD plus the previous cycle's residual."""
        self.note = [""] * n


class Controller:
    """Decides each part's cycle when it reaches B (SimPy process).

    A part that reaches B while the robot is not back is not caught: it rides on
    and falls off at F (thesis §6.3); the log says so.
    """

    def __init__(self, env: simpy.Environment, k: CellConstants, adaptive: bool,
                 fixed: Plan | None, feeder_fed_s: list[float], n_parts: int,
                 conveyor: InputConveyor, output: OutputConveyor, robot: Robot, log: Log):
        self.env, self.k, self.adaptive, self.fixed = env, k, adaptive, fixed
        self.fed_s = feeder_fed_s
        self.n = n_parts
        self.conveyor, self.output, self.robot, self.log = conveyor, output, robot, log
        self.residual_s = k.r3_post_nom + k.r4_nom
        """The previous cycle's TD → K and R IV (step 5.0, 6.2); nominal before the first."""
        self.process = env.process(self.run())

    def next_part(self, i: int, now: float, lag: float, v: float) -> tuple[float, float] | None:
        """(a, b) of the first part after i that can still be caught (see adaptive_plan)."""
        conv, length = self.conveyor, self.k.input_length
        x_now = conv.belt.travel(now)
        for j in range(i + 1, self.n):
            f = self.fed_s[j]
            if f > now + lag:
                return (f - now, length)
            x_fed = conv.x_fed[j]
            if x_fed != x_fed:  # dropped between now and LO: not recorded yet
                x_fed = x_now + v * (f - now)
            d = x_fed + length - (x_now + v * lag)
            if d > 0:
                return (lag, d)
        return None

    def run(self):  # noqa: ANN201 (SimPy generator)
        env, log, k, robot = self.env, self.log, self.k, self.robot
        conveyor, output, adaptive, u_nom = self.conveyor, self.output, self.adaptive, k.u_nom
        r1_pre_time, speed, next_part = k.timing.r1_pre.time, conveyor.belt.speed, self.next_part
        replan_in, replan_out, put = conveyor.replan, output.replan, robot.orders.put
        get, at_bot_s, plans, thesis_s = conveyor.at_bot.get, log.at_bot_s, log.plan, \
            log.thesis_interval_s
        while True:
            i = yield get()
            now = env.now
            at_bot_s[i] = now
            if robot.free_at_s > now + EPS_S:
                log.note[i] = "reached B while the robot was busy: fell off at F"
                continue
            if adaptive:
                v = speed(now + EPS_S)
                lag = r1_pre_time(v)
                plan = adaptive_plan(k, v, next_part(i, now, lag, v), output.gap_now(), lag)
                replan_in(now + lag, plan.input_after_lo, now + plan.cycle, plan.input_next)
                replan_out(now, plan.output_to_g, now + plan.to_g, u_nom)
                log.note[i] = plan.note
            else:
                plan = self.fixed
            plans[i] = plan
            thesis_s[i] = plan.to_g + plan.r3_pre + self.residual_s
            self.residual_s = plan.r3_post + plan.r4
            robot.free_at_s = now + plan.cycle
            put(Order(i, plan.r1_pre, plan.to_g - plan.r1_pre + plan.r3_pre,
                      plan.r3_post + plan.r4))
