"""The robot: regime times from the joint-step table, and its SimPy process.

A regime's time for a tip velocity v is Σ max(ℓ/v, t_min) over its moves
(thesis §6.1): each move takes its length over the velocity unless its slowest
joint's maximum step rate makes it longer.  That total is piecewise linear in
u = 1/v, so :class:`Segment` stores it once as sorted breakpoints and answers
"time for this velocity" and "velocity for this time" with one bisection each,
with no per-move work while the simulation runs.

The tracking regimes (R I, R III) are timed against the belt, not along the
path: a move's "length" there is the belt's travel during it (the path divides
the belt equally, §4.2), so at belt speed v the robot keeps up with the part
unless a joint cannot.  The grasp (release) move that ends at LO (TD) changes the
hand's length (eq. 6.2) and may take longer than the belt's pace.

What a cycle may take is stated once, here (:meth:`RobotTiming.shortest_parts`,
docs/model.md "What a cycle may take"), and read by the plan check
(:class:`cell.sim.policies.check.PlanCheck`, the controller's) and by the
bound on any controller (:mod:`cell.sim.bound`): R I and R III keep their belt's
pace over the whole window, B → F and G → K (the thesis's R III, 4.0 s at 2 in/s,
tracks the output belt to K), at a belt speed no faster than the robot can follow
(the tracking limit), each move floored by its slowest joint at peak rate; R II and
R IV are at least their fastest.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, Any

import numpy as np
import simpy

from cell.arm.motors import Segment
from cell.sim.failure_clock import MOVING_NOT, STOPPED
from cell.sim.mailbox import Mailbox
from cell.sim.records import LET_GO

if TYPE_CHECKING:
    from cell.arm.steptable import StepTable


@dataclass(frozen=True)
class RobotTiming:
    """Everything the controllers need about the robot's speed, built once per scenario.

    Belt-tracking segments are in belt travel (in); R II and R IV in path length.
    Motor floors are at the peak rates (the motors can always give them, §7.2);
    ``r4_nominal_s`` is R IV with the base at its nominal 75 % (thesis 9.9855 s).
    """

    r1_pre: Segment
    """B → LO, belt travel; the grasp move ending at LO included."""
    r1_post: Segment
    """LO → F, belt travel (hand off the belt: motors only)."""
    r2: Segment
    r3_pre: Segment
    """G → TD, output belt travel; the release move ending at TD included."""
    r3_post: Segment
    """TD → K."""
    r4: Segment
    r4_nominal_s: float
    """R IV at the nominal motor rates (the thesis's 9.9855 s; docs/model.md)."""
    input_track_max_in_s: float
    """Fastest input belt the robot can follow before LO (grasp move excluded)."""
    output_track_max_in_s: float
    """Fastest output belt the robot can follow before TD (release move excluded)."""
    r1_length_in: float
    r3_length_in: float
    r2_min_s: float
    r4_min_s: float
    """Fastest R II / R IV: constant peak rates (§6.1) or the minimum-time planner."""

    def r1_time(self, v: float) -> tuple[float, float]:
        """(B → LO, LO → F) times tracking an input belt at v."""
        return self.r1_pre.time(v), self.r1_post.time(v)

    def r3_time(self, u: float) -> tuple[float, float]:
        """(G → TD, TD → K) times tracking an output belt at u."""
        return self.r3_pre.time(u), self.r3_post.time(u)

    def shortest_parts(self, v: float, u: float) -> tuple[float, float, float, float, float, float]:
        """What a cycle may take: the shortest B → LO, LO → F, R II, G → TD, TD → K and R IV with
        the input belt at ``v`` while R I follows it and the output belt at ``u`` while R III
        does, each no faster than the robot can follow (:meth:`fastest_followed`).  A tracking
        regime keeps its belt's pace from the window's start to its end (B → F, G → K), every
        move at least its belt travel over the belt's speed and at least its slowest joint's
        time at peak rate; R II and R IV at the motors' peak (the module's text)."""
        r1a, r1b = self.r1_time(v)
        r3a, r3b = self.r3_time(u)
        return r1a, r1b, self.r2_min_s, r3a, r3b, self.r4_min_s

    def fastest_followed(self, input_max: float, output_max: float) -> tuple[float, float]:
        """The fastest input and output belt speeds the robot can follow: each belt's tracking
        limit, or its ceiling (``input_max``, ``output_max``) where that is lower."""
        return min(self.input_track_max_in_s, input_max), min(self.output_track_max_in_s, output_max)


def build_timing(t: StepTable, fastest: dict[str, float] | None = None) -> RobotTiming:
    """Reduce a solved path to the regime segments (thesis §6.1).

    ``fastest``: the planner's rest-to-rest R II and R IV times, which floor the
    constant-rate ones (``robot.timing: minimum-time``); None for the thesis's model.
    """
    ell, tp = t.velocity_lengths, t.peak_min_times
    rows = {name: np.flatnonzero(mask) for name, mask in t.segment_rows().items()}

    def segment(name: str, drop_last: bool = False) -> Segment:
        r = rows[name][:-1] if drop_last else rows[name]
        return Segment(ell[r], tp[r])

    # what the robot can follow on a belt: the grasp / release move excluded
    track1, track3 = segment("r1_pre", drop_last=True), segment("r3_pre", drop_last=True)
    r2seg, r4seg = segment("r2"), segment("r4")
    r2_min, r4_min = r2seg.floor_s, r4seg.floor_s
    if fastest is not None:
        r2_min, r4_min = max(r2_min, float(fastest["R2"])), max(r4_min, float(fastest["R4"]))
    return RobotTiming(
        r1_pre=segment("r1_pre"), r1_post=segment("r1_post"), r2=r2seg,
        r3_pre=segment("r3_pre"), r3_post=segment("r3_post"), r4=r4seg,
        r4_nominal_s=t.regime_min_time("R4", nominal=True),
        input_track_max_in_s=track1.max_tracking_velocity(),
        output_track_max_in_s=track3.max_tracking_velocity(),
        r1_length_in=t.regime_length("R1"), r3_length_in=t.regime_length("R3"),
        r2_min_s=r2_min, r4_min_s=r4_min)


def timing_to_plain(t: RobotTiming) -> dict[str, Any]:
    """The timing as plain JSON data (for the disk cache); every float kept exactly.

    Raises TypeError if a value is not a float or a list of floats (then it is not stored).
    """
    def plain(value: Any) -> Any:
        if type(value) is float or (type(value) is list and all(type(v) is float for v in value)):
            return value
        raise TypeError(f"not plain: {type(value).__name__}")

    out: dict[str, Any] = {}
    for f in fields(t):
        value = getattr(t, f.name)
        if isinstance(value, Segment):
            out[f.name] = {"segment": {name: plain(v) for name, v in value.saved().items()}}
        else:
            out[f.name] = plain(value)
    return out


def timing_from_plain(data: dict[str, Any]) -> RobotTiming:
    """The timing back from :func:`timing_to_plain`'s data."""
    values: dict[str, Any] = {}
    for f in fields(RobotTiming):
        value = data[f.name]
        if isinstance(value, dict):
            value = Segment.of_saved(value["segment"])
        elif type(value) is not float:
            raise TypeError(f"{f.name}: not a float")
        values[f.name] = value
    return RobotTiming(**values)


# --------------------------------------------------------------------------- process
class Robot:
    """The arm as a SimPy process: told an order, runs it, hands the part over.

    An order is one transfer cycle as the controller sends it (step 6.1): the
    part's record (the robot writes its lift-off and touch-down instants), and
    B → LO and B → TD in seconds from now; the robot is free again the cycle's
    B → B later.

    The robot owns its state: ``free_at_s``, when it will be back at B, is set the
    moment it is told an order.  What can stop it is handed to it: ``stops``
    (:class:`cell.sim.failures.RobotStops`: failures, planned stops, the belts it
    tracks) and ``wear`` (:class:`cell.sim.wear_clock.WearStops`: a worn motor
    replaced once the cycle is done); None: nothing can.
    """

    def __init__(self, env: simpy.Environment, output: Mailbox, stops: Any = None,
                 wear: Any = None):
        self.env = env
        self.orders: Mailbox = Mailbox(env)
        """Cycles to run, from the controller: (part, B → LO, B → TD, the instant) tuples."""
        self.output = output
        """Where parts are set down (the output conveyor's mailbox)."""
        self.free_at_s = 0.0
        """When the robot is (or will be) back at B, ready for a part."""
        self.stops = stops
        """What can stop the robot mid-cycle (None: nothing)."""
        self.wear = wear
        """Its motors' wear, stopping it once back at B when one wears out (None: no wear)."""
        if stops is not None:
            stops.robot = self
        self.process = env.process(self.run())

    def loss(self, now: float) -> int:
        """The limit bit of a part that reaches B while the robot is not back: let go
        (lost to downtime, if a stop kept the robot away)."""
        return LET_GO if self.stops is None else self.stops.loss(now)

    def order(self, part: Any, to_lo_s: float, to_td_s: float, cycle_s: float,
              now: float) -> None:
        """Start a cycle now, at the clock's ``now`` (the robot must be free): lift-off
        ``to_lo_s``, touch-down ``to_td_s`` and back at B ``cycle_s`` from now (and a worn
        motor's replacement after, if one wears out in it)."""
        if self.wear is not None:
            cycle_s = self.wear.cycle_s(part, to_lo_s, to_td_s, cycle_s, now)
        self.free_at_s = now + cycle_s
        self.orders.put((part, to_lo_s, to_td_s, now))

    def run(self):  # noqa: ANN201 (SimPy generator)
        """Each order taken the instant it is given (the order carries that instant).  When
        nothing can stop the robot before it is back at B, its lift-off and touch-down are
        known now: the lift-off is written and the part handed to the output conveyor due at
        its touch-down, one event; the way back needs none, since no order comes before
        ``free_at_s``.  Otherwise the cycle's legs run one by one, each a timeout that a
        stop interrupts (SimPy's machine shop), the robot held while ``stops`` holds it."""
        env, get, stops = self.env, self.orders.get, self.stops
        set_down, placed = self.output.put_after, self.output.put
        while True:
            part, to_lo_s, to_td_s, now = yield get()
            legs = None if stops is None else stops.begin(part, to_lo_s, to_td_s)
            if legs is None:  # nothing can stop it: the cycle's instants are known now
                part.pick_s = now + to_lo_s
                set_down((part, now + to_td_s), to_td_s)
                continue
            rest = part.plan.cycle
            for i, leg in enumerate(legs):
                rest -= leg
                stops.at_leg, left = i, leg
                while left > 0.0:
                    start = env.now
                    try:
                        if stops.held(i):
                            stops.doing(STOPPED if stops.stop is not None else MOVING_NOT,
                                        math.inf)
                            yield env.event()  # until whatever holds the robot lets go
                        # a planned stop due: the robot will not be free for a part at B
                        stops.doing(i, start + left + max(rest, 0.0)
                                    if stops.maintenance_due is None else math.inf)
                        yield env.timeout(left)
                        left = 0.0
                    except simpy.Interrupt:
                        if stops.moving_since == stops.moving_since:
                            left = max(left - (env.now - start), 0.0)
                if i == 0 and stops.part is not None:  # lifted (not lost in a stop)
                    part.pick_s = env.now
                elif i == 3 and stops.part is not None:  # touch-down: taken now, its instant
                    placed((stops.set_down(), env.now))
            stops.at_rest()
