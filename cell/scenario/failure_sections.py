"""The ``wear:`` and ``failures:`` sections of a scenario file: motor wear, breakdowns,
repairs and planned stops (docs/model.md, "When equipment fails"; docs/wear.md).  Split from
:mod:`cell.scenario.sections`, whose bounds they share; :mod:`cell.scenario.schema` puts them
together with the rest."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Field, SerializerFunctionWrapHandler, model_serializer

from cell.scenario.fields import Section
from cell.scenario.sections import MAX_HOURS, MAX_TIME_S, finite


# --------------------------------------------------------------------------- wear
class WearSettings(Section):
    """Motor wear from how hard each cycle drives the joints (SPEC §10; docs/wear.md): an
    inverse power law in the step rate, carried by the cumulative exposure model, Weibull in
    the exposure (Nelson 1990, *Accelerated Testing*).  Off by default: no value here is
    known for the MICROBOT; each is an assumption to sweep."""

    enabled: bool = Field(False, strict=True)
    """Wear the motors and stop the robot when one wears out; off, nothing changes."""
    exponent: float = finite(1.0, ge=0.0, le=20.0)
    """p of η(S) = η0 (S0/S)^p, S a joint's step rate over its rated maximum.  1: life in
    steps, the rolling-bearing case (L10h ∝ 1/speed); 0: life in hours of motion whatever
    the speed (a stepper's winding heats with its near-constant current)."""
    rated_life_h: float = finite(5000.0, gt=0.0, le=1e7)
    """η0: a motor's Weibull characteristic life in hours of motion at ``reference_stress``."""
    reference_stress: float = finite(0.75, gt=0.0, le=1.0)
    """S0: the stress the rated life is quoted at; the motors' nominal 75 % (§7.2)."""
    shape: float = finite(2.0, gt=0.0, le=20.0)
    """β, the Weibull shape in the exposure: above 1, the motor wears out."""
    repair_h: float = finite(4.0, ge=0.0, le=MAX_TIME_S / 3600.0)
    """Hours the robot is down while a worn motor is replaced."""


# --------------------------------------------------------------------------- failures
class TimeDistribution(Section):
    """A time (s) as a scipy.stats distribution, named and parametrised as ``arrivals`` is:
    by scipy's ``params``, or by its mean (``mean_s`` or ``mean_h``) and, but for ``expon``,
    its ``shape`` or ``cv``: ``weibull_min``, ``gamma``, ``lognorm`` (cell.scenario.spread)."""

    distribution: str = "expon"
    """Any continuous distribution in scipy.stats, by name (by its mean: see above)."""
    params: dict[str, Annotated[float, Field(strict=True, allow_inf_nan=False)]] = Field(
        default_factory=dict)
    """Its parameters by scipy's names (``scale``, ``loc``, shapes), in seconds."""
    mean_s: float | None = finite(None, gt=0.0, le=MAX_HOURS * 3600.0)
    """The mean time in seconds (or ``mean_h``, not both)."""
    mean_h: float | None = finite(None, gt=0.0, le=MAX_HOURS)
    """The mean time in hours (or ``mean_s``, not both)."""
    shape: float | None = finite(None, gt=0.0, le=1e4)
    """With the mean: scipy's shape parameter, weibull_min's c, gamma's a, lognorm's s (or
    ``cv``, not both; ``expon`` takes neither)."""
    cv: float | None = finite(None, gt=0.0, le=10.0)
    """With the mean: the coefficient of variation, sd / mean (or ``shape``, not both)."""

    @model_serializer(mode="wrap")
    def _given_only(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """Mean and spread only where given: a time by ``params`` dumps as before they were."""
        d: dict[str, Any] = handler(self)
        return {k: v for k, v in d.items() if k not in ("mean_s", "mean_h", "shape", "cv")
                or v is not None}


class EquipmentFailures(Section):
    """How one piece of equipment fails and is repaired (docs/model.md, "When equipment fails")."""

    time_to_failure: TimeDistribution
    """Time from a repair to the next failure, counted on ``clock``."""
    time_to_repair: TimeDistribution
    """Time a repair takes once a crew is on it."""
    clock: Literal["operating", "calendar", "working"] = "operating"
    """``operating``: the failure clock runs only while the equipment works (the robot in
    motion); ``calendar``: whenever it is up; ``working``: whenever it is up in the calendar's
    working time (needs a ``calendar:`` section)."""


class RobotFailures(EquipmentFailures):
    """The arm's failures; a failure stops it mid-move."""

    part_in_hand: Literal["finish", "scrap"] = "finish"
    """What becomes of a part held when the arm fails: set down after the repair, or scrapped."""


class RepairSettings(Section):
    """The repair crews: a failure waits for a free one (machine-repairman)."""

    crews: int = Field(1, strict=True, ge=1, le=1000)
    """Crews working at once."""
    hours: list[tuple[str, str]] | None = None
    """With a calendar: the crews' hours on the calendar's working days, clock spans as its
    shifts (``[["06:00", "14:00"]]``: the first shift only), less its breaks; a repair stands
    outside them.  Absent: the calendar's working time."""

    @model_serializer(mode="wrap")
    def _given_only(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """``hours`` only where given: a section without it dumps as before it existed."""
        d: dict[str, Any] = handler(self)
        return {k: v for k, v in d.items() if k != "hours" or v is not None}


class MaintenanceSettings(Section):
    """Planned stops of the robot, each started once the robot is back at B."""

    every_h: float = finite(..., gt=0.0, le=MAX_HOURS)
    """Hours between the starts of planned stops (from the start of the run)."""
    duration_min: float = finite(..., gt=0.0, le=MAX_HOURS * 60)
    """Minutes each stop lasts."""
    off_shift: bool = Field(False, strict=True)
    """With a calendar: each stop waits, once due, until the cell stands for a time off shift
    it fits in (a night, a weekend; the week's longest if none is long enough) and is done
    then, out of the planned busy time."""

    @model_serializer(mode="wrap")
    def _given_only(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        """``off_shift`` only when true: a section without it dumps as before it existed."""
        d: dict[str, Any] = handler(self)
        return {k: v for k, v in d.items() if k != "off_shift" or v}


class FailureSettings(Section):
    """Breakdowns, repairs and planned stops; absent: nothing ever stops."""

    robot: RobotFailures | None = None
    input_belt: EquipmentFailures | None = None
    output_belt: EquipmentFailures | None = None
    sensor: EquipmentFailures | None = None
    """The look-ahead: while it is down the controller reads no next part."""
    repair: RepairSettings | None = None
    """Absent: every failure is repaired at once (as many crews as failures)."""
    maintenance: MaintenanceSettings | None = None
