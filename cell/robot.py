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
unless a joint cannot.  Before LO (and before TD) the robot must keep up; the
grasp (release) move that ends at LO (TD) changes the hand's length (eq. 6.2)
and may take longer than the belt's pace; after LO (TD) the hand is off the belt
and the move times are only floored by the motors (§4.3 c).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import simpy

from cell.errors import CellError
from cell.mailbox import Mailbox
from cell.motors import Segment
from cell.scenario import Scenario


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
    """R IV at the nominal motor rates (the thesis's 9.9855 s; SPEC §4)."""
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


def build_timing(s: Scenario) -> RobotTiming:
    """Solve the path once and reduce it to the regime segments (thesis §6.1)."""
    from cell.steptable import StepTable

    t = StepTable.from_scenario(s)
    ell, tp = t.velocity_lengths, t.peak_min_times
    rows = {name: np.flatnonzero(mask) for name, mask in t.segment_rows().items()}

    def segment(name: str, drop_last: bool = False) -> Segment:
        r = rows[name][:-1] if drop_last else rows[name]
        return Segment(ell[r], tp[r])

    # what the robot can follow on a belt: the grasp / release move excluded
    track1, track3 = segment("r1_pre", drop_last=True), segment("r3_pre", drop_last=True)
    r2seg, r4seg = segment("r2"), segment("r4")
    r2_min, r4_min = r2seg.floor_s, r4seg.floor_s
    if s.robot.timing == "minimum-time":
        try:
            from cell.mintime import fastest_regime_times
        except ImportError:
            raise CellError("robot.timing = 'minimum-time' needs the minimum-time planner "
                            "(cell.mintime.fastest_regime_times), which is not available; "
                            "use robot.timing: constant-rate") from None
        fastest = fastest_regime_times(s, t)
        r2_min, r4_min = max(r2_min, float(fastest["R2"])), max(r4_min, float(fastest["R4"]))
    return RobotTiming(
        r1_pre=segment("r1_pre"), r1_post=segment("r1_post"), r2=r2seg,
        r3_pre=segment("r3_pre"), r3_post=segment("r3_post"), r4=r4seg,
        r4_nominal_s=t.regime_min_time("R4", nominal=True),
        input_track_max_in_s=track1.max_tracking_velocity(),
        output_track_max_in_s=track3.max_tracking_velocity(),
        r1_length_in=t.regime_length("R1"), r3_length_in=t.regime_length("R3"),
        r2_min_s=r2_min, r4_min_s=r4_min)


@functools.lru_cache(maxsize=16)
def _cached_timing(cell: Any, path: Any, part: Any, robot: Any, mintime: Any,
                   source: str) -> RobotTiming:
    return build_timing(Scenario(cell=cell, path=path, part=part, robot=robot,
                                 mintime=mintime, source=source))


def robot_timing(s: Scenario) -> RobotTiming:
    """:func:`build_timing`, cached on the sections that shape the path and the motors.

    A sweep's replications (and both policies) share one solved path per process.
    With the minimum-time planner the scenario's file is part of the key (the
    planner may read a dynamics file beside it).
    """
    source = s.source if s.robot.timing == "minimum-time" else ""
    return _cached_timing(s.cell, s.path, s.part, s.robot, s.mintime, source)


# --------------------------------------------------------------------------- process
class Order(NamedTuple):
    """One transfer cycle as the controller sends it (step 6.1): regime times, s."""

    part: Any
    to_lo_s: float
    """B → LO (R I up to lift-off)."""
    lo_to_td_s: float
    """LO → F → G → TD."""
    td_to_bot_s: float
    """TD → K → B (rest of R III and R IV)."""


class Robot:
    """The arm as a SimPy process: takes an :class:`Order`, runs it, hands the part over.

    ``lo`` and ``td`` are the current cycle's lift-off and touch-down events (any
    process may wait on them); ``free_at_s`` is when it will be back at B.  One
    timeout per leg up to TD: a regime's moves are summed, never simulated one by
    one.  The way back (TD → K → B) needs no event: the controller sends no order
    before ``free_at_s``, and the robot starts the next one when it comes.
    """

    def __init__(self, env: simpy.Environment, output: Mailbox, log: Any):
        self.env = env
        self.log = log
        """Where lift-off and touch-down instants are written (``pick_s``, ``touchdown_s``)."""
        self.orders: Mailbox = Mailbox(env)
        """Cycles to run, from the controller."""
        self.output = output
        """Where parts are set down (the output conveyor's mailbox)."""
        self.free_at_s = 0.0
        """When the robot is (or will be) back at B, ready for a part."""
        self.lo: simpy.Event | None = None
        self.td: simpy.Event | None = None
        self.process = env.process(self.run())

    def run(self):  # noqa: ANN201 (SimPy generator)
        env, log, timeout = self.env, self.log, self.env.timeout
        pick_s, touchdown_s, put = log.pick_s, log.touchdown_s, self.output.put
        get = self.orders.get
        while True:
            order: Order = yield get()
            part, to_lo, to_td = order.part, order.to_lo_s, order.to_lo_s + order.lo_to_td_s
            # LO is an event others may wait on; the robot itself moves on to TD.
            self.lo = timeout(to_lo)
            pick_s[part] = env.now + to_lo
            self.td = td = timeout(to_td)
            yield td
            touchdown_s[part] = env.now
            put(part)
