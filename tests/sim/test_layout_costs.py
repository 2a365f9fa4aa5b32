"""A layout's options cost per hour (docs/usage.md, "Energy and cost"; docs/layout.md): a robot
per station, the adaptive controller and the sensor where a station has them, a buffer place
per place, each station's counted."""

from __future__ import annotations

import pytest

from cell.scenario.schema import load_scenario
from cell.sim.simulation import simulate

OPTIONS = {"robot": 6.0, "buffer_place": 0.5, "adaptive_controller": 1.0, "sensor": 0.25}


def test_each_station_s_options_are_counted():
    base = {"run.parts": 60, "costs": {"options_per_h": OPTIONS}}
    alone = simulate(load_scenario("baseline", base)).summary
    line = simulate(load_scenario("baseline", {
        **base, "buffer": {"places": 2},
        "stations": [{"name": "c", "placement": "downstream", "offset_in": 40.0,
                      "controller": {"policy": "non-adaptive"}, "buffer": {"places": 0},
                      "sensor": {"lookahead": "sensor"}}]})).summary
    assert alone.cost_per_h == pytest.approx(6.0 + 1.0)  # one robot, adaptive; nothing lost
    # the first: robot, adaptive, 2 places; the catcher: robot and its sensor
    assert line.cost_per_h == pytest.approx(  # part_value 0: only the options cost
        (6.0 + 1.0 + 2 * 0.5) + (6.0 + 0.25))
