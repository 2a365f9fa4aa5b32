"""The animation's runs: the thesis's cell, both policies on the same parts, simulated
once for every test file here."""

from __future__ import annotations

import pytest

from cell.reporting.animation.movie import simulate_scenes
from cell.reporting.animation.scene import Scene
from cell.scenario.schema import Scenario, default_scenario

from .helpers import COUNT, FIRST


@pytest.fixture(scope="package")
def scenario() -> Scenario:
    return default_scenario().with_overrides({"controller.nominal_cycle_s": 22.5872})


@pytest.fixture(scope="package")
def scenes(scenario: Scenario) -> list[Scene]:
    """Both policies, the same parts (common random numbers)."""
    return simulate_scenes(scenario, ["adaptive", "non-adaptive"], FIRST, COUNT)
