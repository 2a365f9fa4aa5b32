"""A calendar's checks against the rest of the scenario: the settings that only a calendar
gives a meaning (the ``working`` failure clock, a crew's ``repair.hours``, maintenance off
shift, ``run.days`` / ``run.weeks``) refused without one, and the calendar's own week and a
crew's hours checked (:func:`cell.scenario.calendar_section.working_week`)."""

from __future__ import annotations

from typing import Any

from cell.plumbing.errors import ScenarioError
from cell.scenario.calendar_section import working_week
from cell.scenario.failure_spec import EQUIPMENT


def check_calendar(s: Any, file: object) -> None:
    """Refuse what needs a calendar without one, and a calendar with no working time."""
    f, cal = s.failures, s.calendar
    if cal is not None:
        working_week(cal, file)
        if f is not None and f.repair is not None and f.repair.hours is not None:
            working_week(cal, file, f.repair.hours, "failures.repair.hours")
        if s.wear.enabled and (f is None or f.robot is None):
            raise ScenarioError(file, "wear.enabled", True, "with a calendar, wear is counted "
                                "by the robot's failure clock: give failures.robot")
        return
    why = "needs a calendar: section (the working time it counts)"
    if f is None:
        return
    for name in EQUIPMENT:
        mode = getattr(f, name)
        if mode is not None and mode.clock == "working":
            raise ScenarioError(file, f"failures.{name}.clock", mode.clock, why)
    if f.repair is not None and f.repair.hours is not None:
        raise ScenarioError(file, "failures.repair.hours", [list(h) for h in f.repair.hours], why)
    if f.maintenance is not None and f.maintenance.off_shift:
        raise ScenarioError(file, "failures.maintenance.off_shift", True, why)
