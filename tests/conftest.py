"""Shared fixtures: the repository's scenario files and the thesis's cell, solved once."""

from __future__ import annotations

import pytest

from cell import catalog
from cell.assembly import constants, robot_timing, step_table
from cell.scenario import Scenario, default_scenario, load_scenario


@pytest.fixture(scope="session")
def thesis_cell() -> Scenario:
    """The thesis's cell: every default, and the ideal cycle the thesis quotes (22.5872 s;
    left out, the nominal cycle is the arrivals' own mean, 22.586 s for eq. 6.9)."""
    return default_scenario().with_overrides({"controller.nominal_cycle_s": 22.5872})


@pytest.fixture(scope="session")
def baseline() -> Scenario:
    return load_scenario(catalog.path("baseline"))


@pytest.fixture(scope="session")
def table(thesis_cell):
    """The thesis's path solved into its joint-step table."""
    return step_table(thesis_cell)


@pytest.fixture(scope="session")
def timing(thesis_cell):
    return robot_timing(thesis_cell)


@pytest.fixture(scope="session")
def k(thesis_cell, timing):
    """The policies' constants for the thesis's cell."""
    return constants(thesis_cell, timing)
