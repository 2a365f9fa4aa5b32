"""The ``energy:`` section of a scenario file: the power each piece of equipment draws in
each of its states, and whether the arm's motion energy comes from its dynamic model
(docs/usage.md, "Energy and cost"; docs/model.md, "Energy of the arm's motion").  Split from
:mod:`cell.scenario.sections`; :mod:`cell.scenario.schema` puts it together with the rest.

Each piece of equipment takes a power only for the states it has (those of ``states.csv``),
and ``off_shift`` (every piece of equipment has it, with or without a calendar): a power for
any other state is refused as an unknown key, naming the file, the key and the value.
"""

from __future__ import annotations

from typing import Literal

from cell.plumbing.errors import ScenarioError
from cell.scenario.fields import Section
from cell.scenario.sections import finite

#: The most a piece of equipment is taken to draw in any state (W): a bound on slips.
MAX_POWER_W = 1e6


def watts(default: float) -> float:
    """A power in watts: finite, not negative."""
    result: float = finite(default, ge=0.0, le=MAX_POWER_W)
    return result


class RobotPower(Section):
    """The robot's draw (W) in each of its states; every value an assumption (docs/usage.md)."""

    busy: float = watts(120.0)
    """In motion (with ``arm: dynamics``, replaced by the arm's own energy: docs/usage.md)."""
    waiting: float = watts(40.0)
    """Up and still with a part on its way to B."""
    idle: float = watts(40.0)
    """Up and still with nothing on the input belt."""
    down: float = watts(5.0)
    """Failed: waiting for a crew or under repair."""
    maintenance: float = watts(5.0)
    """In a planned stop."""
    off_shift: float = watts(2.0)
    """Off shift (a calendar's time off)."""


class BeltPower(Section):
    """A belt's draw (W) in each of its states."""

    running: float = watts(60.0)
    """Up (running at whatever speed the controller sets)."""
    down: float = watts(0.0)
    """Failed."""
    off_shift: float = watts(0.0)
    """Off shift."""


class SensorPower(Section):
    """The look-ahead sensor's draw (W) in each of its states."""

    up: float = watts(3.0)
    """Working (with ``sensor.lookahead: sensor``)."""
    down: float = watts(0.0)
    """Failed."""
    off_shift: float = watts(0.0)
    """Off shift."""


class PowerSettings(Section):
    """Watts per state of each piece of equipment (state-based energy)."""

    robot: RobotPower = RobotPower()
    input_belt: BeltPower = BeltPower()
    output_belt: BeltPower = BeltPower()
    sensor: SensorPower = SensorPower()


class EnergySettings(Section):
    """The run's energy (docs/usage.md, "Energy and cost"); absent: none is computed."""

    power_w: PowerSettings = PowerSettings()
    """State-based: watts per state of each piece of equipment."""
    arm: Literal["dynamics", "none"] = "none"
    """``dynamics``: the arm's motion energy per transfer from its dynamic model
    (``mintime.dynamics_file``); ``none``: the robot's ``busy`` power alone."""

    def power(self, equipment: str, state: str) -> float:
        """The power (W) of ``equipment`` in ``state``."""
        value: float = getattr(getattr(self.power_w, equipment), state)
        return value


def check_energy(energy: EnergySettings | None, dynamics_file: str | None, file: object) -> None:
    """``arm: dynamics`` needs a dynamic model (``mintime.dynamics_file``)."""
    if energy is not None and energy.arm == "dynamics" and not dynamics_file:
        raise ScenarioError(file, "energy.arm", "dynamics", "needs the arm's dynamic model, "
                            "and mintime.dynamics_file names none")


# --------------------------------------------------------------------------- costs
def money(default: float = 0.0) -> float:
    """An amount of money (any currency, the same throughout): finite, not negative."""
    result: float = finite(default, ge=0.0, le=1e12)
    return result


class OptionCosts(Section):
    """The amortised cost per hour of the cell's options, each counted as the scenario has it."""

    sensor: float = money()
    """The look-ahead sensor (counted with ``sensor.lookahead: sensor``)."""
    buffer_place: float = money()
    """A buffer place (per place: ``buffer.places``, each station's)."""
    robot: float = money()
    """A robot (per robot: one, and one per station of ``stations:``)."""
    adaptive_controller: float = money()
    """The adaptive controller (counted with ``controller.policy: adaptive``)."""


class CostSettings(Section):
    """What the run costs (docs/usage.md, "Energy and cost"); absent: no cost measured."""

    part_value: float = money()
    """The value of a part lost (ridden off, or scrapped from the hand)."""
    energy_per_kwh: float = money()
    """The price of a kWh (the ``energy:`` section's energy; without one, none)."""
    downtime_per_h: float = money()
    """The cost of an hour the robot is down (failed or worn, a crew's wait included)."""
    repair: float = money()
    """The cost of a repair (each failure of any piece of equipment, a worn motor's included)."""
    maintenance: float = money()
    """The cost of a planned maintenance stop."""
    options_per_h: OptionCosts = OptionCosts()
