"""Minimum-time motion along the transfer path (Shin & McKay 1983; SPEC §9).

``fastest_regime_times(scenario)`` gives the robot's fastest R II and R IV when
``robot.timing: minimum-time``; ``cell.mintime.planner`` is the phase-plane
algorithm itself, ``cell.mintime.regimes`` applies it to the cell.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    from cell.scenario import Scenario
    from cell.steptable import StepTable

__all__ = ["fastest_regime_times"]


def fastest_regime_times(scenario: Scenario, table: StepTable | None = None) -> dict[str, float]:
    """{"R2": seconds, "R4": seconds}: the planner's rest-to-rest times (cached per scenario).

    ``table``: the scenario's solved path, if the caller has it already.
    """
    from .regimes import fastest_regime_times as _f

    return _f(scenario, table)
