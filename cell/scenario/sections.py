"""The sections of a scenario file: one pydantic model each, every key documented.

Each section's keys, their defaults (the thesis's cell, with its section or
equation) and their bounds.  :mod:`cell.scenario.schema` puts them together, validates a
whole scenario and reads files.  Magnitudes are bounded so that no input can
exhaust the machine or overflow: lengths and coordinates within 1,000 in, belt
speeds up to 1,000 in/s, times up to 10⁶ s, at most 10,000 moves per regime, 10⁷
parts per run, 10⁵ planner grid points, and seeds below 2¹²⁸.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Field, field_validator

from cell.scenario import registry
from cell.scenario.fields import Section

MAX_LENGTH_IN = 1000.0
MAX_SPEED_IN_S = 1000.0
MAX_TIME_S = 1e6
MAX_PARTS = 10_000_000
MAX_MOVES = 10_000
MAX_GRID_POINTS = 100_000
MAX_SEED = 2**128
MAX_HOURS = 1e5


def finite(default: Any = None, *, gt: float | None = None, ge: float | None = None,
         le: float | None = None) -> Any:
    """A finite number field (ints accepted, booleans and text refused) with bounds."""
    return Field(default, strict=True, allow_inf_nan=False, gt=gt, ge=ge, le=le)


Coord = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=-MAX_LENGTH_IN,
                               le=MAX_LENGTH_IN)]
Point = tuple[Coord, Coord, Coord]
Positive = Annotated[float, Field(strict=True, allow_inf_nan=False, gt=0.0, le=1e9)]
NonNegative = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=0.0, le=1e9)]
PositiveFive = tuple[Positive, Positive, Positive, Positive, Positive]
#: A motor makes at least one step per radian, or it cannot follow any path.
StepsPerRad = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=1.0, le=1e7)]
Angle = Annotated[float, Field(strict=True, allow_inf_nan=False, ge=-360.0, le=360.0)]
Range = tuple[Angle, Angle]


# --------------------------------------------------------------------------- cell
class LayoutSettings(Section):
    """Where the robot stands (thesis §4.1, §6.1, eq. 6.1)."""

    robot_base_in: Point = (-8.0, 8.0, 0.0)
    """Base axis on the table, global frame (§4.1)."""
    shoulder_height_in: float = finite(7.68, gt=0.0, le=MAX_LENGTH_IN)
    """Shoulder above the table (§6.1)."""
    robot_yaw_deg: float = finite(-45.0, ge=-360.0, le=360.0)
    """Robot frame = global rotated about z by this (eq. 6.1)."""
    belt_width_in: float = finite(8.0, gt=0.0, le=MAX_LENGTH_IN)
    """Both conveyors (§4.1); a part must fit on them; otherwise used for drawings only."""


# --------------------------------------------------------------------------- path
class MoveSettings(Section):
    """Moves per regime; 459 in all, 460 points (§4.2)."""

    R1: int = Field(96, strict=True, ge=2, le=MAX_MOVES)
    """Divisions along the input belt, B → F."""
    R2: int = Field(117, strict=True, ge=1, le=MAX_MOVES)
    """Divisions of the F → G arc."""
    R3: int = Field(96, strict=True, ge=2, le=MAX_MOVES)
    """Divisions along the output belt, G → K."""
    R4: int = Field(150, strict=True, ge=1, le=MAX_MOVES)
    """150 equal chords reproduce the R IV length 35.5424 in that Table 7.1's Vavg implies."""


class PathSettings(Section):
    """The transfer path B → F → G → K → B (thesis §4.2, Fig. 9)."""

    bot_in: Point = (-16.0, 0.0, 3.0)
    """B, beginning of tracking on the input belt (§4.2)."""
    f_in: Point = (-8.0, 0.0, 3.0)
    """F, end of input tracking (§4.2)."""
    g_in: Point = (0.0, 8.0, 3.0)
    """G, beginning of output tracking (§4.2)."""
    eot_in: Point = (0.0, 16.0, 3.0)
    """K, end of tracking on the output belt (§4.2)."""
    pick_height_in: float = finite(1.0, gt=0.0, le=MAX_LENGTH_IN)
    """Tool-centre height at lift-off LO: the cube's centre (§4.2, §6.2 f)."""
    place_height_in: float = finite(1.0, gt=0.0, le=MAX_LENGTH_IN)
    """Tool-centre height at touch-down TD (§4.2)."""
    lo_from_bot_in: float = finite(4.0, gt=0.0, le=MAX_LENGTH_IN)
    """Distance B → LO; the thesis does not place LO: mid-window (docs/model.md)."""
    td_from_g_in: float = finite(4.0, gt=0.0, le=MAX_LENGTH_IN)
    """Distance G → TD: mid-window, as LO."""
    moves: MoveSettings = MoveSettings()


# --------------------------------------------------------------------------- part
class PartSettings(Section):
    """The parts: oriented cubes (thesis §6.2 c, f)."""

    size_in: float = finite(2.0, gt=0.0, le=MAX_LENGTH_IN)
    """Cube edge; also the finger opening while holding it (§6.2 f)."""
    weight_oz: float = finite(4.0, ge=0.0, le=1e6)
    """Load carried from LO to TD (§6.2 f)."""


# --------------------------------------------------------------------------- robot
class JointLimitSettings(Section):
    """Joint ranges (degrees) in the DH convention of Table 3.1 (docs/model.md)."""

    theta1: Range = (-90.0, 90.0)
    """Base ±90°."""
    theta2: Range = (-35.0, 144.0)
    """Shoulder +144° / -35°."""
    theta3: Range = (-149.0, 0.0)
    """Elbow 0° / -149°."""
    theta4: Range = (-180.0, 0.0)
    """Wrist pitch: the thesis's ±90° about the in-line pose, which is θ4 = -90° here."""
    theta5: Range = (-180.0, 180.0)
    """Wrist roll ±180°."""

    def as_list(self) -> list[tuple[float, float]]:
        return [self.theta1, self.theta2, self.theta3, self.theta4, self.theta5]


class HandSettings(Section):
    """Hand length against finger opening G, eq. 6.2 (corrected: docs/sources.md)."""

    l1_in: float = finite(1.884, ge=0.0, le=MAX_LENGTH_IN)
    """L1 of w11 = L1 + √(L2² − (G − G0)²/2)."""
    l2_in: float = finite(1.700, gt=0.0, le=MAX_LENGTH_IN)
    """L2 of eq. 6.2."""
    g0_in: float = finite(1.520, ge=0.0, le=MAX_LENGTH_IN)
    """G0 of eq. 6.2."""
    open_in: float = finite(2.5, gt=0.0, le=MAX_LENGTH_IN)
    """Finger opening with no part; ASSUMED (the thesis gives no figure)."""


class MotorSettings(Section):
    """Stepper drives (thesis §6.1): rates linear in the load, 75 % nominal."""

    steps_per_rad: tuple[StepsPerRad, StepsPerRad, StepsPerRad, StepsPerRad, StepsPerRad] = (
        1125.0, 1125.0, 672.0, 241.0, 241.0)
    """TeachMover half-steps per radian: base, shoulder, elbow, pitch, roll."""
    max_rate_no_load_rad_s: PositiveFive = (0.4194527, 0.36, 0.82, 2.02, 2.02)
    """TeachMover no-load speeds, except the base: CALIBRATED to 0.4194527 rad/s
    (TeachMover 0.42) so that R IV at the nominal 75 % takes the thesis's 9.9855 s."""
    max_rate_full_load_rad_s: PositiveFive = (0.37, 0.15, 0.23, 1.31, 1.31)
    """TeachMover speeds carrying the full load (1 lb)."""
    full_load_oz: float = finite(16.0, gt=0.0, le=1e6)
    """The load of those full-load figures."""
    nominal_fraction: float = finite(0.75, gt=0.0, le=1.0)
    """Nominal operation at 75 % of rated output, peak on request (§7.2)."""


class RobotSettings(Section):
    """The MICROBOT arm (thesis §3, Table 3.1; link lengths from the TeachMover)."""

    l2_in: float = finite(7.0, gt=0.0, le=MAX_LENGTH_IN)
    """Upper arm (TeachMover)."""
    l3_in: float = finite(7.0, gt=0.0, le=MAX_LENGTH_IN)
    """Forearm (TeachMover)."""
    joint_limits_deg: JointLimitSettings = JointLimitSettings()
    hand: HandSettings = HandSettings()
    motors: MotorSettings = MotorSettings()
    timing: Literal["constant-rate", "minimum-time"] = "constant-rate"
    """How the fastest R II and R IV are found: constant maximum step rates (the
    thesis) or the minimum-time planner (Shin & McKay)."""


# --------------------------------------------------------------------------- belts
class BeltSettings(Section):
    """The two conveyors (thesis §4.3, §5.2)."""

    input_nominal_in_s: float = finite(3.0, gt=0.0, le=MAX_SPEED_IN_S)
    """Nominal input belt speed (§5.2)."""
    output_nominal_in_s: float = finite(2.0, gt=0.0, le=MAX_SPEED_IN_S)
    """Nominal output belt speed (§5.2)."""
    spacing_in: float = finite(45.0, gt=0.0, le=MAX_LENGTH_IN)
    """Required spacing of parts on the output belt (§4.3 f)."""
    spacing_tol_in: float = finite(0.25, ge=0.0, le=MAX_LENGTH_IN)
    """Tolerance on that spacing (§4.3 f)."""
    input_min_in_s: float = finite(1.5, gt=0.0, le=MAX_SPEED_IN_S)
    """Slowest the adaptive controller may run the input belt; ASSUMED: half the nominal
    speed (§6.2 a gives belts unlimited range; docs/assumptions.md)."""
    input_max_in_s: float = finite(12.0, gt=0.0, le=MAX_SPEED_IN_S)
    """Fastest the input belt may run; ASSUMED (§6.2 a gives belts unlimited range)."""
    output_min_in_s: float = finite(0.25, gt=0.0, le=MAX_SPEED_IN_S)
    """Slowest the output belt may run; ASSUMED: a set-down part then clears a 2 in part's
    size before the next touch-down even at the robot's shortest cycle (docs/assumptions.md)."""
    output_max_in_s: float = finite(12.0, gt=0.0, le=MAX_SPEED_IN_S)
    """Fastest the output belt may run; ASSUMED, as the input's."""
    input_length_in: float | None = finite(None, gt=0.0, le=MAX_LENGTH_IN * 10)
    """Feeder drop point to B; the thesis gives none.  Empty: two nominal cycles of
    belt travel (2 × 3.0 × 22.5872 = 135.52 in), so the next part is usually on the
    belt when the controller looks ahead (§5.2)."""


# --------------------------------------------------------------------------- arrivals
WEIBULL_SHAPE = 1.0 / 0.2038
"""Eq. 6.9's exponent is 1/shape."""


class RateProfile(Section):
    """A rate piecewise constant over a repeating period (docs/usage.md, "Arrivals whose rate changes")."""

    period_h: float = finite(..., gt=0.0, le=MAX_HOURS)
    """Hours after which the profile repeats: a shift (8), a day (24), a week (168)."""
    rates: list[Positive] = Field(..., strict=True)
    """Relative rates of the pieces, each > 0, normalised to a time-weighted mean of 1 (the long-run
    mean gap stays the distribution's): ``[1.2, 1.2, 1, 1, 1, 1, 1, 1]``, 20 % faster for 2 h."""
    starts_h: list[NonNegative] | None = None
    """Hour of the period at which each piece starts (the first at 0, increasing, each
    before ``period_h``).  Empty: equal pieces."""
    run_start_h: float = finite(0.0, ge=0.0, le=MAX_HOURS)
    """The hour of the period at which the run starts (below ``period_h``): 0, its start."""


class ArrivalSettings(Section):
    """Inter-arrival times of parts (thesis §6.2 d, eq. 6.9)."""

    distribution: str = "weibull_min"
    """Any continuous distribution in scipy.stats, by name."""
    params: dict[str, Annotated[float, Field(strict=True, allow_inf_nan=True)]] = Field(
        default_factory=lambda: {"c": WEIBULL_SHAPE, "loc": 17.6019, "scale": 5.4342})
    """Its parameters by scipy's names; the default is eq. 6.9."""
    mean_s: float | None = finite(None, gt=0.0, le=MAX_TIME_S)
    """With ``cv``: the mean inter-arrival time; the family's shape and scale are then
    derived from the two (no location) and ``params`` is not used."""
    cv: float | None = finite(None, gt=0.0, le=10.0)
    """With ``mean_s``: the coefficient of variation (sd / mean) of the inter-arrival time;
    ``gamma``, ``weibull_min``, ``lognorm`` and ``expon`` (shifted; cv ≤ 1) take it."""
    trace_csv: str | None = None
    """A CSV of observed inter-arrival times (column ``interarrival_s``), used in
    order instead of the distribution; relative to the scenario file."""
    profile: RateProfile | None = None
    """A rate that changes over a shift, a day or a week; absent: a constant rate."""


# --------------------------------------------------------------------------- controller
class ControllerSettings(Section):
    """Operating policy (thesis §5.3, §6.3)."""

    policy: str = "adaptive"
    """A registered policy: ``adaptive`` (§5.3), ``non-adaptive`` (§6.3), or a plug-in."""
    nominal_cycle_s: float | None = finite(None, gt=0.0, le=MAX_TIME_S)
    """The ideal transfer time of §5.3, the mean inter-arrival time.  Empty: the mean of
    the arrivals (the distribution's, or the trace's); the thesis quotes 22.5872 s."""
    ideal_cycle_s: float | None = finite(None, gt=0.0, le=MAX_TIME_S)
    """The robot's fixed cycle for the non-adaptive policy (Table 7.1, column 1);
    shortened in R IV only.  Empty: the nominal cycle."""

    @field_validator("policy")
    @classmethod
    def _known_policy(cls, value: str) -> str:
        if not registry.known(value):
            raise ValueError("must be one of " + ", ".join(registry.names()))
        return value


class RunSettings(Section):
    """How long a run is and where its random numbers come from (§6.3)."""

    parts: int = Field(500, strict=True, ge=1, le=MAX_PARTS)
    """Parts to arrive (§6.3: 500)."""
    warmup_parts: Annotated[int, Field(strict=True, ge=0, le=MAX_PARTS)] | Literal["auto"] = 0
    """Parts left out of every measure as warm-up: a number, or ``auto`` (MSER-5 on the
    delivery intervals).  The thesis's terminating 500-part runs keep 0."""
    seed: int = Field(1984, strict=True, ge=0, lt=MAX_SEED)
    """Root of every random stream (numpy SeedSequence)."""
    hours: float | None = finite(None, gt=0.0, le=MAX_HOURS)
    """The run's length in hours instead of parts: the parts that come in that time, the run
    stopped at its end (parts still in the cell then are counted as such).  Give one of
    run.parts, run.hours, run.days and run.weeks."""
    days: int | None = Field(None, strict=True, ge=1, le=36_600)
    """With a calendar: the run's length in working days (days of the calendar with working
    time, counted from the start's date), the run stopped at the end of the last one's last
    shift."""
    weeks: int | None = Field(None, strict=True, ge=1, le=5_200)
    """With a calendar: the run's length in whole weeks (7 × 24 h from the start)."""


class MinTimeSettings(Section):
    """Minimum-time planner settings (Shin & McKay 1983; docs/model.md)."""

    grid_points: int = Field(460, strict=True, ge=3, le=MAX_GRID_POINTS)
    """Grid points per regime (R II, R IV), s scaled to [0, 1]; 460 as the thesis's path."""
    rate_fraction: float = finite(1.0, gt=0.0, le=1.0)
    """Joint velocity bounds = the motors' step rates at the regime's load (§6.1) times
    this: 1.0 is the peak, as in the thesis's minimum feasible cycle (§7.2)."""
    acceleration_bounds: bool = Field(False, strict=True)
    """Apply ``qddot_max_rad_s2``; off, as in baseline.yaml: the dynamic model sets the
    accelerations alone."""
    qddot_max_rad_s2: PositiveFive = (2.0, 2.0, 4.0, 8.0, 8.0)
    """Joint acceleration bounds; ASSUMED (a stepper indexer's ramp; the thesis has none)."""
    dynamics_file: str | None = "microbot_dynamics.yaml"
    """YAML of the rigid-body model (beside the scenario file, else the built-in file of that
    name), as in baseline.yaml; empty: no torque bounds."""


# --------------------------------------------------------------------------- quality
class QualitySettings(Section):
    """Which parts OEE counts as good (ISO 22400-2's good quantity; docs/model.md, "OEE as
    plants define it")."""

    rule: Literal["set_down", "spacing"] = "set_down"
    """``set_down``: every part set down on the output belt is good, a part scrapped from the
    hand in a failure is not; ``spacing``: a part set down outside the spacing tolerance
    (``belts``, §4.3 f) is not good either."""


# --------------------------------------------------------------------------- sensor
class SensorSettings(Section):
    """What the adaptive controller knows of the next part (docs/model.md, "The look-ahead")."""

    lookahead: Literal["ideal", "sensor"] = "ideal"
    """``ideal``: the thesis's assumption (§5.3 step 1.0), the next part's arrival known when
    the transfer starts, even before the feeder drops it (an idealisation); ``sensor``: a
    physical sensor that reports parts as they pass it, with the error, delay and misses
    below.  Left out: ``ideal``, so the thesis's results reproduce (docs/model.md)."""
    position_in: float | None = finite(None, ge=0.0, le=MAX_LENGTH_IN)
    """How far before B the sensor sees a part (in).  Empty: at the feeder's drop point
    (``belts.input_length_in``); it cannot be further up than that, nor behind B."""
    noise_sd_in: float = finite(0.0, ge=0.0, le=MAX_LENGTH_IN)
    """Standard deviation of the error on the position it reports (in, normal)."""
    latency_s: float = finite(0.0, ge=0.0, le=MAX_TIME_S)
    """How long after a part passes it the report reaches the controller (s): a known, fixed
    delay, which the controller dates the report back by; a part is seen that much later."""
    miss_probability: float = finite(0.0, ge=0.0, le=1.0)
    """The chance that a part passes unreported (each part drawn on its own)."""
    margin_s: float | None = finite(None, ge=0.0, le=MAX_TIME_S)
    """How long after the robot is back the adaptive controller aims the next part at B, so
    that a part the sensor misjudges is not let go for arriving a moment early (s).  Empty:
    0 with the ideal look-ahead (the thesis's exact aim); with a sensor, three standard
    deviations of its error, in time at the nominal input speed."""
