"""One record type per row of each output file, and the part in flight: :class:`PartRecord`, a row of
``parts.csv``, one per arriving part, made once when the part is done; :class:`RunSummary`, the one row
of ``summary.csv`` (and of a sweep's ``replications.csv``); :class:`BeltChange`, a row of ``belts.csv``.

The fields, in order, *are* the columns; each field's docstring is its meaning (docs/usage.md's column tables
are checked against them). One writer for each field. A part travels through the processes as a
:class:`Part`, whose slots are each written once, by the process that owns the event (the feeder its drop,
the input conveyor its arrival at B, the controller its plan, the robot its lift-off, the output conveyor its
set-down); its limits (:data:`LIMITS`) are bits the run's log collects. The row (:class:`PartRecord`,
immutable) is made from these once, by the run's log, when the part is done: whatever a column derives from
(a regime time from the plan, ``picked`` and ``missed`` from the limit bits, the thesis's columns from the
accounting) is derived then, in one place. A write-once record per part rather than an immutable record per
event (as Ciw's): one object a part instead of four, and no row is made at all when nobody keeps or streams
the rows (``make bench``'s case). ``tests/sim/test_one_writer.py`` checks that each slot has its one writer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any, NamedTuple

from cell.sim.part import Part  # noqa: F401 - the part in flight, re-exported

NAN = math.nan

#: The limits a part's cycle can hit, as bits of a flag word and as names in parts.csv's
#: ``limits`` column (docs/model.md, "Departures from the thesis's controller"):
LIMITS = (
    "input_floor",      # the input belt held at belts.input_min_in_s (step 3.2 asked slower)
    "input_ceiling",    # the input belt held at belts.input_max_in_s (step 3.1 asked faster)
    "input_tracking",   # the input belt held to the fastest the robot can track (step 6.3)
    "output_floor",     # the output belt held at belts.output_min_in_s: spacing off (step 5.0)
    "output_ceiling",   # the output belt held at belts.output_max_in_s: spacing off (step 5.0)
    "r2_peak",          # R II at the motors' peak rates (steps 2.1-2.3)
    "r4_peak",          # R IV at the base's peak rate (step 3.2)
    "let_go",           # reached B while the robot was busy: fell off at F (§6.3)
    "spacing_off",      # set down outside the spacing tolerance (§4.3 f)
    "held_at_feeder",   # dropped later than it came: the belt had not cleared a part's size
    "lost_downtime",    # reached B (or was being picked) while the robot was stopped: rode off
    "scrapped",         # in the hand when the robot failed, scrapped (failures.robot.part_in_hand)
    "spacing_wait",     # spacing off: the robot waited longer than the output floor allows
    "spacing_unforeseen",  # spacing off: a wait the look-ahead did not foresee (belt slowed late)
    "buffer_full",      # found the buffer full and rode on past it (buffer.when_full: ride_off)
)
LIMIT_BIT = {name: 1 << i for i, name in enumerate(LIMITS)}
(INPUT_FLOOR, INPUT_CEILING, INPUT_TRACKING, OUTPUT_FLOOR, OUTPUT_CEILING, R2_PEAK, R4_PEAK,
 LET_GO, SPACING_OFF, HELD_AT_FEEDER, LOST_DOWNTIME, SCRAPPED, SPACING_WAIT, SPACING_UNFORESEEN,
 BUFFER_FULL) = (1 << i for i in range(len(LIMITS)))
#: The one encoding of a part lost at B: it rode off (let go, lost to downtime, or past a full
#: buffer).  A part scrapped in the hand is ``SCRAPPED``; every other part done was set down.
RODE_OFF = LET_GO | LOST_DOWNTIME | BUFFER_FULL


class LimitCount(NamedTuple):
    """How summary.csv counts the parts that hit a limit."""

    field: str
    """The :class:`RunSummary` field (the column) holding the count."""
    label: str
    """What the count is, as ``cell run`` prints it."""


#: The limits counted in summary.csv, by name, in the order ``cell run`` lists them as
#: "limits hit" (``let_go`` and ``spacing_off`` are reported as the parts lost and the
#: spacings outside the tolerance):
LIMIT_COUNTS: dict[str, LimitCount] = {
    "r4_peak": LimitCount("limit_r4_peak", "R IV at the base's peak rate"),
    "r2_peak": LimitCount("limit_r2_peak", "R II at the motors' peak"),
    "input_floor": LimitCount("limit_input_floor",
                              "picks with the input belt at its floor (the part after each let go)"),
    "input_ceiling": LimitCount("limit_input_ceiling", "input belt at its ceiling (robot waited)"),
    "input_tracking": LimitCount("limit_input_tracking", "input belt held to the robot's tracking limit"),
    "output_floor": LimitCount("limit_output_floor", "output belt at its floor"),
    "output_ceiling": LimitCount("limit_output_ceiling", "output belt at its ceiling"),
    "held_at_feeder": LimitCount("parts_held", "held at the feeder (belt not clear)"),
    "spacing_wait": LimitCount("limit_spacing_wait",
                               "spacing off: a wait longer than the output floor allows"),
    "spacing_unforeseen": LimitCount("limit_spacing_unforeseen",
                                     "spacing off: a wait the look-ahead did not foresee"),
}


def limit_names(flags: int) -> str:
    """The names of the limits in a flag word, space-separated, in :data:`LIMITS` order."""
    names = LIMIT_NAMES.get(flags)
    if names is None:
        names = LIMIT_NAMES[flags] = " ".join(name for i, name in enumerate(LIMITS)
                                              if flags >> i & 1)
    return names


LIMIT_NAMES: dict[int, str] = {}  # :func:`limit_names`' answers so far, by flag word


class PartRecord(NamedTuple):
    """What happened to one part, from the feeder to the output belt (or the floor): parts.csv's row."""

    part: int
    """1 … N, in order of arrival (the part's :attr:`Part.index` + 1)."""
    arrival_s: float = NAN
    """When the feeder dropped it on the input belt."""
    interarrival_s: float = NAN
    """T_i, its inter-arrival time (eq. 6.9 draw, or the trace)."""
    at_bot_s: float = NAN
    """When it reached B, the beginning of tracking."""
    picked: bool = False
    """Picked up by the robot (the robot was back at B when it arrived): no :data:`RODE_OFF`
    bit in its limits."""
    missed: bool = False
    """Reached B while the robot was busy (or stopped): rode on and fell off at F (§6.3); the
    negation of ``picked``, both read from the limits' :data:`RODE_OFF` bits."""
    missed_thesis: bool = False
    """Lost under the thesis's bookkeeping (docs/accounting.md)."""
    pick_s: float = NAN
    """Lift-off (LO): the hand closes on the part."""
    touchdown_s: float = NAN
    """Touch-down (TD): the part is set on the output belt."""
    delivery_interval_s: float = NAN
    """Wall clock: time since the previous part's touch-down."""
    motion_cycle_s: float = NAN
    """The robot's motion B → B for this part."""
    thesis_interval_s: float = NAN
    """The thesis's "time between deliveries" under the policy's own accounting."""
    ip_wallclock: float = NAN
    """IP (eq. 5.1) = T(i+1) / delivery interval."""
    ip_thesis: float = NAN
    """IP in the thesis's accounting."""
    input_speed_in_s: float = NAN
    """Input belt speed while R I tracks the part."""
    output_speed_in_s: float = NAN
    """Output belt speed until the robot reaches G (step 5.0)."""
    spacing_in: float = NAN
    """Distance to the previous part on the output belt."""
    v_r1_in_s: float = NAN
    """R I's length over its time: the regime's average tip velocity."""
    v_r2_in_s: float = NAN
    """R II's length over its time."""
    v_r3_in_s: float = NAN
    """R III's length over its time."""
    v_r4_in_s: float = NAN
    """R IV's length over its time."""
    r1_s: float = NAN
    """Time in R I (B → F)."""
    r2_s: float = NAN
    """Time in R II (F → G)."""
    r3_s: float = NAN
    """Time in R III (G → K)."""
    r4_s: float = NAN
    """Time in R IV (K → B)."""
    feed_delay_s: float = 0.0
    """How long the feeder held the part back, the belt not having cleared a part's size."""
    limits: str = ""
    """The limits this part's cycle hit (names from :data:`LIMITS`, space-separated)."""
    energy_j: float | None = None
    """The arm's motion energy of this transfer, J, electrical (only with ``energy.arm: dynamics``)."""
    station: str | None = None
    """The station that handled it last: set it down, or let it go for good (only with
    ``stations:``; docs/layout.md)."""
    buffer_wait_s: float | None = None
    """Seconds it stood in buffers, summed over the stations it came to (only with a
    ``buffer:`` section, the scenario's or a station's; docs/layout.md)."""


@dataclass(slots=True)
class RunSummary:
    """One run in one row: counts, both accountings, spacing and belt extremes."""

    scenario: str = ""
    """The scenario's name."""
    policy: str = ""
    """The control policy."""
    seed: Any = None
    """The root seed (an int, or entropy/spawn key of a sweep's stream)."""
    ideal_cycle_s: float = NAN
    """The cycle the policy plans for (Table 7.1, column 1)."""
    parts_arrived: int = 0
    """Parts dropped on the input belt."""
    parts_delivered: int = 0
    """Parts set down on the output belt."""
    parts_missed: int = 0
    """Parts lost on the wall clock (fell off at F)."""
    parts_in_cell: int = 0
    """Arrived but neither delivered nor lost when the run ended."""
    parts_missed_thesis: int = 0
    """Parts lost under the thesis's bookkeeping."""
    actual_cycle_wallclock_s: float = NAN
    """Mean time between consecutive set-downs."""
    actual_cycle_thesis_s: float = NAN
    """Actual cycle in the thesis's accounting."""
    parts_per_hr_wallclock: float = NAN
    """3600 / wall-clock actual cycle."""
    parts_per_hr_thesis: float = NAN
    """3600 / the thesis's actual cycle (Table 7.1's column)."""
    vavg_r4_in_s: float = NAN
    """R IV's length over its mean time (Table 7.1's column)."""
    ip_wallclock: float = NAN
    """Mean IP on the wall clock."""
    ip_thesis: float = NAN
    """Mean IP in the thesis's accounting."""
    cycle_vs_nominal_pct: float = NAN
    """The thesis's actual cycle against the ideal one, %."""
    ip_thesis_memoryless: float = NAN
    """The adaptive IP with each next arrival counted from the current pick-up."""
    cycle_vs_nominal_memoryless_pct: float = NAN
    """The same reading's cycle against the ideal one, %."""
    spacing_min_in: float = NAN
    """Closest spacing on the output belt."""
    spacing_max_in: float = NAN
    """Widest spacing on the output belt."""
    spacing_outside_tol: int = 0
    """Spacings outside 45 ± 0.25 in (§4.3 f)."""
    limit_input_floor: int = 0
    """Parts after whose pick-up step 3.2 held the input belt at its floor, R IV and R II at
    their fastest: the *next* part still reaches B before the robot is back and is let go
    (counted in ``parts_missed``); the part counted here was picked."""
    limit_input_ceiling: int = 0
    """Parts whose input belt was held at its ceiling (the robot waited)."""
    limit_input_tracking: int = 0
    """Parts after which the input belt was held to the robot's tracking limit."""
    limit_output_floor: int = 0
    """Parts whose output belt was held at its floor (spacing off)."""
    limit_output_ceiling: int = 0
    """Parts whose output belt was held at its ceiling (spacing off)."""
    limit_r2_peak: int = 0
    """Parts with R II at the motors' peak rates."""
    limit_r4_peak: int = 0
    """Parts with R IV at the base's peak rate."""
    parts_held: int = 0
    """Parts the feeder held back until the belt had cleared a part's size."""
    feed_delay_max_s: float = NAN
    """The longest such hold."""
    input_speed_max_in_s: float = NAN
    """Fastest the input belt ran."""
    input_speed_min_in_s: float = NAN
    """Slowest the input belt ran."""
    output_speed_min_in_s: float = NAN
    """Slowest output belt speed asked before G."""
    output_speed_max_in_s: float = NAN
    """Fastest output belt speed asked before G."""
    r1_nominal_s: float = NAN
    """R I at the nominal input belt."""
    r2_nominal_s: float = NAN
    """R II's share of the nominal cycle."""
    r4_s: float = NAN
    """Mean R IV time of the parts picked."""
    nominal_cycle_s: float = NAN
    """The ideal cycle the controller aimed at (§5.3)."""
    nominal_from: str = ""
    """``scenario`` (controller.nominal_cycle_s), ``arrivals`` (their mean), or ``fastest``
    (the arrivals come faster than the robot's fastest cycle)."""
    mean_interarrival_s: float = NAN
    """The arrivals' mean inter-arrival time (the distribution's or the trace's)."""
    fastest_cycle_s: float = NAN
    """The robot's fastest cycle: R II and R IV at the motors' peak."""
    offered_load: float = NAN
    """Fastest cycle over mean inter-arrival time: 1 or more, the cell cannot keep up."""
    warmup_parts: int = 0
    """Parts left out of every measure above as warm-up (run.warmup_parts)."""
    thesis_slack_s: float = NAN
    """The calibrated slack of the thesis's bookkeeping (non-adaptive), s."""
    sim_end_s: float = NAN
    """Simulated time when the run ended."""
    robot_busy_fraction: float = NAN
    """Share of the run the robot was in motion (``offered_load`` is a ratio of rates, not this)."""
    robot_waiting_fraction: float = NAN
    """Share of the run the robot was up and still with a part on its way to B."""
    robot_idle_fraction: float = NAN
    """Share of the run the robot was up and still with nothing on the input belt."""
    robot_down_fraction: float = NAN
    """Share of the run the robot was down (failed: waiting for a crew or under repair)."""
    robot_maintenance_fraction: float = NAN
    """Share of the run the robot was in planned maintenance."""
    planned_time_s: float = NAN
    """OEE's planned busy time, s: the run less planned stops (ISO 22400-2; docs/model.md)."""
    availability: float = NAN
    """OEE's A: the robot's time in motion / planned busy time."""
    performance: float = NAN
    """OEE's P: nominal cycle × parts produced (set down or scrapped) / time in motion."""
    quality: float = NAN
    """OEE's Q: good parts / parts produced, by ``quality.rule``."""
    oee: float = NAN
    """A × P × Q = nominal cycle × good parts / planned busy time (the whole run's)."""
    loss_downtime: float = NAN
    """Share of the planned busy time the robot was down (failed or worn)."""
    loss_starved: float = NAN
    """Share the robot was up and still with no part to pick."""
    loss_blocked: float = NAN
    """Share the robot was up and still while the output belt stood."""
    loss_speed: float = NAN
    """Share lost to pace, A (1 − P) (negative: faster than the nominal cycle)."""
    loss_quality: float = NAN
    """Share lost to parts produced but not good, A P (1 − Q); with OEE the losses sum to 1."""
    service_level: float = NAN
    """Parts delivered / parts arrived."""
    parts_lost_downtime: int = 0
    """Parts that rode off because the robot was stopped (down or in maintenance), or was
    still making up a cycle a stop had held (counted in ``parts_missed`` too)."""
    parts_scrapped: int = 0
    """Parts in the hand when the robot failed, scrapped (failures.robot.part_in_hand)."""
    robot_failures: int = 0
    """Times the robot failed (planned stops not counted)."""
    mtbf_observed_s: float = NAN
    """The robot's time up (not down, not in maintenance) per failure."""
    mttr_observed_s: float = NAN
    """The robot's time down per failure (the wait for a crew included)."""
    limit_spacing_wait: int = 0
    """Parts set down off spacing because the robot waited so long that even the output belt
    at its floor from the last touch-down could not have kept 45 in (spacing contract)."""
    limit_spacing_unforeseen: int = 0
    """Parts set down off spacing after a wait the look-ahead did not foresee (a part let go,
    missed by the sensor or misjudged): the output belt was slowed too late."""
    parts_bound: int = 0
    """The most parts any controller could deliver from the same arrivals with the same robot
    and belts (a bound: each part's window at B, picks a fastest cycle apart; cell.sim.bound)."""
    energy_kwh: float | None = None
    """The run's energy, kWh (only with an ``energy:`` section; docs/usage.md)."""
    energy_per_good_part_wh: float | None = None
    """``energy_kwh`` per good part (``quality.rule``; the whole run's), Wh."""
    cost_per_good_part: float | None = None
    """The run's cost per good part (only with a ``costs:`` section; docs/usage.md)."""
    cost_per_h: float | None = None
    """The run's cost per hour of the run (only with a ``costs:`` section)."""
    arm_energy_per_transfer_j: float | None = None
    """The mean of parts.csv's ``energy_j``, J (only with ``energy.arm: dynamics``)."""
    line_throughput_per_h: float | None = None
    """The line's parts set down by a station nothing is fed from, per hour of the run (only
    with ``buffer:`` or ``stations:``; docs/layout.md)."""
    line_wip_mean: float | None = None
    """The line's work in process: the time-average number of parts between their drop on
    the input belt and leaving the line (set down by its last station, or lost for good)."""

    def __getitem__(self, name: str) -> Any:
        return getattr(self, name)

    def as_dict(self) -> dict[str, Any]:
        return {name: getattr(self, name) for name in SUMMARY_COLUMNS + [
            c for c in OPTIONAL_COLUMNS if getattr(self, c) is not None]}


@dataclass(slots=True, frozen=True)
class BeltChange:
    """A belt runs at a new speed from an instant on."""

    belt: str
    """``input`` or ``output``."""
    from_s: float
    """The instant the speed takes effect."""
    speed_in_s: float
    """The speed from then on (in/s)."""


@dataclass(slots=True, frozen=True)
class StateSpan:
    """A piece of equipment in one state over an interval (a row of ``states.csv``)."""

    equipment: str
    """``robot``, ``input_belt``, ``output_belt`` or ``sensor``."""
    state: str
    """robot: busy / waiting / idle / down / maintenance; belts: running / down; sensor: up / down."""
    from_s: float
    """When the state began."""
    to_s: float
    """When it ended (the run's end for the last)."""
    station: str | None = None
    """The station's name, with ``stations:`` or ``buffer:`` (stations.csv's ``station``)."""


@dataclass(slots=True, frozen=True)
class Stop:
    """A failure or a planned stop (a row of ``failures.csv``)."""

    equipment: str
    """The piece of equipment that stopped."""
    cause: str
    """``failure`` (a drawn time to failure), ``wear`` (a worn motor) or ``maintenance``."""
    from_s: float
    """When it stopped."""
    to_s: float
    """When it ran again (repair done, crew wait included); the run's end if still down."""
    part: Any
    """The part the robot held or was picking when it failed (empty otherwise)."""
    station: str | None = None
    """The station's name, with ``stations:`` or ``buffer:`` (stations.csv's ``station``)."""


def columns(record_type: type) -> list[str]:
    """The CSV columns of a record type: its fields, in order."""
    named = getattr(record_type, "_fields", None)  # a NamedTuple's
    return list(named) if named is not None else [f.name for f in fields(record_type)]


PART_COLUMNS = columns(PartRecord)[:-3]  # energy_j, station, buffer_wait_s: with their sections
#: parts.csv's columns that appear only with their sections, in order.
OPTIONAL_PART_COLUMNS = ("energy_j", "station", "buffer_wait_s")
OPTIONAL_COLUMNS = tuple(columns(RunSummary)[columns(RunSummary).index("energy_kwh"):])  # the sections' own
SUMMARY_COLUMNS = [c for c in columns(RunSummary) if c not in OPTIONAL_COLUMNS]  # those: with sections
BELT_COLUMNS = columns(BeltChange)
STATE_COLUMNS = columns(StateSpan)[:-1]  # station: with a layout (docs/layout.md)
STOP_COLUMNS = columns(Stop)[:-1]
