"""What every control policy shares: the cell's constants, the plan of one cycle,
the view of the cell a policy decides from, and the thesis-style accounting.

A policy (thesis §5.3, §6.3) is a class with a ``name`` and one decision,
:meth:`Policy.plan`: given the cell's state when a part reaches B with the
robot free, the regime times of the part's cycle and, if it steers them, the
belt speeds.  Its :meth:`Policy.accounting` counts the run the way the thesis
would have (docs/accounting.md); the default is step 6.2's motion time.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from array import array
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol

import numpy as np

from cell.sim import accounting
from cell.sim.records import RunSummary
from cell.sim.robot import RobotTiming


@dataclass(frozen=True)
class CellConstants:
    """What the policies know of the cell, computed once per scenario."""

    timing: RobotTiming
    v_nom: float
    """Nominal input belt speed, in/s (§5.2)."""
    u_nom: float
    """Nominal output belt speed, in/s (§5.2)."""
    cycle_nom: float
    """The ideal cycle the policies aim at (§5.3): the mean inter-arrival time, or the
    robot's fastest cycle when the arrivals are faster than that."""
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
    """R II's share of the ideal cycle: what the other regimes leave of it."""
    r1_nom: float
    """R I at the nominal input belt: belt pace to LO plus the motor floor after it."""
    input_min: float = 0.0
    """Slowest input belt speed the controller may ask (``belts.input_min_in_s``)."""
    output_min: float = 0.0
    """Slowest output belt speed (``belts.output_min_in_s``)."""
    part_size: float = 2.0
    """Cube edge: parts on a belt are never closer than this (centre to centre)."""
    input_absorb: float = 0.0
    """The slowest input belt whose longer R I tracking R II can still absorb (step 2.2):
    a belt left slower than this would lengthen the next cycle (docs/model.md)."""
    mean_interarrival_s: float = float("nan")
    """Mean inter-arrival time of the arrivals (the distribution's or the trace's)."""
    lookahead_margin_s: float = 0.0
    """The adaptive controller aims the next part at B this long after the robot is back
    (``sensor.margin_s``; 0 with the ideal look-ahead, as the thesis)."""
    nominal_from: str = "scenario"
    """Where ``cycle_nom`` came from: ``scenario`` (``controller.nominal_cycle_s``),
    ``arrivals`` (their mean) or ``fastest`` (the arrivals are faster than the robot)."""
    floor_gap_in: float = field(init=False, repr=False, compare=False)
    """The spacing contract's threshold: the most the last part set down may have travelled
    when the next part reaches B for 45 in to be kept with the output belt at its floor until
    G (R I + R II at their nominal sum) and at nominal from G to TD.  Set once, at
    construction (a constant of the cell, like the others)."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "floor_gap_in", self.spacing - self.u_nom * self.r3_pre_nom
                           - self.output_min * (self.r1_nom + self.r2_nom) - 1e-6)


    @property
    def shortest_cycle_s(self) -> float:
        """The nominal cycle with R IV at the base's peak rate (Table 7.1's last row)."""
        return self.cycle_nom - (self.r4_nom - self.timing.r4_min_s)

    @property
    def fastest_cycle_s(self) -> float:
        """The robot's fastest cycle: R II and R IV at the motors' peak, belts at nominal."""
        t = self.timing
        return self.r1_nom + t.r2_min_s + self.r3_pre_nom + self.r3_post_nom + t.r4_min_s

    @property
    def offered_load(self) -> float:
        """Fastest cycle over mean inter-arrival time: 1 or more, the cell cannot keep up."""
        return self.fastest_cycle_s / self.mean_interarrival_s


@dataclass(slots=True, kw_only=True)
class Plan:
    """One transfer cycle: regime times (s), belt speeds (in/s) and what went wrong.

    A named record: built with keywords and read by name, never by position (a slotted
    dataclass, as quick to build and read as the tuple it replaces).  A policy may hand
    the same plan out for every part (the fixed cycle does), so nobody changes one.
    """

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
    limits: int = 0
    """The limits hit (bits of :data:`cell.sim.records.LIMIT_BIT`)."""
    steers_belts: bool = True
    """Whether the belt speeds above are commands (False: the belts are left alone)."""
    output_floor_at: float = math.inf
    """The spacing contract (docs/model.md): seconds from the start of this cycle at which
    the output belt drops to its floor until the next part's plan (inf: not planned)."""


class CellView(Protocol):
    """The cell as a policy sees it when a part reaches B and the robot is free."""

    k: CellConstants

    def input_speed(self) -> float:
        """The input belt's speed now (R I tracks the part at it)."""

    def next_part(self, lag: float, v: float) -> tuple[float, float] | None:
        """(a, b): the next part that can still be caught reaches B a + b/w s from now if
        the input belt runs at w from LO (``lag`` s from now) on; None if none is coming."""

    def output_gap(self) -> float | None:
        """How far the last part set down has travelled on the output belt (None: none yet)."""

    def since_touchdown(self) -> float | None:
        """Seconds since the last part was set down (None: none yet)."""


class Policy(ABC):
    """A control policy: decides each part's cycle (subclass and :func:`cell.scenario.registry.register`)."""

    name: ClassVar[str]

    def __init__(self, k: CellConstants, controller: Any, file: object = None):
        """``controller``: the scenario's ``controller`` section; ``file`` for error messages."""
        self.k = k

    @property
    def ideal_cycle_s(self) -> float:
        """The cycle this policy plans for (reported beside the results)."""
        return self.k.cycle_nom

    @abstractmethod
    def plan(self, view: CellView) -> Plan:
        """The cycle of the part now at B."""

    def accounting(self) -> Accounting:
        """How the thesis would count this policy's run (default: step 6.2's motion time)."""
        return MotionTimeAccounting(self)


class Accounting:
    """Counts a run part by part, then sums it up; parts come in order, each once.

    ``part`` counts a part as it completes, from what was recorded of it (its plan, whether
    it was picked, its inter-arrival time): the thesis's interval and whether the thesis
    counts it lost; ``last`` gives those of the part just counted, for its row (with its IP);
    ``finish`` fills the summary's columns.  The per-part values are kept in flat arrays, so
    a long run costs a few bytes per part.
    """

    def __init__(self, policy: Policy):
        self.policy = policy
        self.interval = array("d")
        self.lost = array("b")

    def part(self, plan: Any, picked: bool, interarrival_s: float) -> None:
        raise NotImplementedError

    def last(self, next_interarrival_s: float) -> tuple[bool, float, float]:
        """The part counted last: (lost in the thesis's accounting, its interval, its IP)."""
        d = self.interval[-1]
        return bool(self.lost[-1]), d, next_interarrival_s / d

    def finish(self, s: RunSummary, start: int, picked_r4_s: np.ndarray,
               t_next: np.ndarray) -> None:
        """Fill ``s``'s thesis columns from part ``start`` on (after the warm-up);
        ``t_next``: every part's next inter-arrival time, ``picked_r4_s``: the R IV times
        of the parts picked after the warm-up."""
        raise NotImplementedError

    def _lost_after(self, start: int) -> int:
        return int(np.frombuffer(self.lost, dtype=np.int8)[start:].sum()) if len(self.lost) else 0


class MotionTimeAccounting(Accounting):
    """Step 6.2: the time between deliveries is the robot's motion time to TD plus the
    previous cycle's residual (idle waits not counted); IP = T(i+1) / that; a part is
    lost when it is lost on the wall clock."""

    def __init__(self, policy: Policy):
        super().__init__(policy)
        k = policy.k
        self._residual = k.r3_post_nom + k.r4_nom
        """The last planned cycle's TD → K and R IV (step 5.0, 6.2); nominal before the first."""

    def part(self, plan: Any, picked: bool, interarrival_s: float) -> None:
        d = math.nan
        if plan is not None:  # step 6.2: motion time to TD plus the previous cycle's residual
            d = plan.to_g + plan.r3_pre + self._residual
            self._residual = plan.r3_post + plan.r4
            if not picked:
                d = math.nan
        self.interval.append(d)
        self.lost.append(not picked)

    def finish(self, s: RunSummary, start: int, picked_r4_s: np.ndarray,
               t_next: np.ndarray) -> None:
        thesis = accounting.thesis_adaptive(t_next[start:], np.frombuffer(self.interval)[start:])
        s.parts_missed_thesis = self._lost_after(start)
        s.actual_cycle_thesis_s = float(thesis.actual_cycle_s)
        s.ip_thesis = float(thesis.mean_ip)
        s.cycle_vs_nominal_pct = accounting.pct_off(s.actual_cycle_thesis_s,
                                                    self.policy.ideal_cycle_s)
        s.r4_s = float(picked_r4_s.mean()) if picked_r4_s.size else math.nan


#: A policy's factory as the registry holds it.
PolicyFactory = Callable[[CellConstants, Any, object], Policy]
