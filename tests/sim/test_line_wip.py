"""The line's throughput and work in process (docs/layout.md "Measures") against Little's law
on its sample path: over a run that starts and ends empty, the time-average number of parts in
the line equals the rate they came at times their mean time in it, each part's time read from
parts.csv (drop to set-down at the last station, or to the last B it passed if lost)."""

from __future__ import annotations

import numpy as np
import pytest

from cell.scenario.schema import load_scenario
from cell.sim.simulation import simulate


def _line(scale: float, when_full: str) -> dict:
    return {"run.parts": 400, "run.seed": 7, "controller.policy": "non-adaptive",
            "controller.ideal_cycle_s": 22.0,
            "arrivals": {"distribution": "expon", "params": {"loc": 0.0, "scale": scale}},
            "buffer": {"places": 3, "when_full": when_full},
            "stations": [{"name": "next", "placement": "series", "transfer_in": 60.0,
                          "controller": {"policy": "non-adaptive", "ideal_cycle_s": 20.5},
                          "buffer": {"places": 2}}]}


@pytest.fixture(scope="module")
def lossless():
    return simulate(load_scenario("baseline", _line(30.0, "hold_feeder")), keep_belts=False)


@pytest.fixture(scope="module")
def lossy():
    return simulate(load_scenario("baseline", _line(16.0, "ride_off")), keep_belts=False)


def test_a_two_station_line_s_wip_is_throughput_times_time_in_line(lossless):
    r, parts = lossless.summary, lossless.parts
    assert r.parts_missed == 0 and r.parts_delivered == r.parts_arrived  # nothing lost
    assert r.line_throughput_per_h == pytest.approx(r.parts_delivered / r.sim_end_s * 3600.0)
    in_line = parts.touchdown_s - parts.arrival_s  # the last station's set-down: series
    assert (parts.station == "next").all()
    assert r.line_wip_mean == pytest.approx(
        r.line_throughput_per_h / 3600.0 * in_line.mean(), rel=1e-9)
    # more than the two robots can hold: parts stood in the buffers and rode the transfer
    assert r.line_wip_mean > lossless.station_rows[0].busy_fraction


def test_a_lossy_line_s_wip_counts_lost_parts_until_they_leave(lossy):
    r, parts = lossy.summary, lossy.parts
    assert r.parts_missed > 0
    left = np.where(np.isfinite(parts.touchdown_s), parts.touchdown_s, parts.at_bot_s)
    rate = len(parts) / r.sim_end_s  # every part that came
    assert r.line_wip_mean == pytest.approx(rate * (left - parts.arrival_s).mean(), rel=1e-9)
    assert r.line_throughput_per_h * r.sim_end_s / 3600.0 == pytest.approx(r.parts_delivered)


def test_the_line_s_columns_only_with_a_layout(lossless):
    assert {"line_throughput_per_h", "line_wip_mean"} <= set(lossless.summary.as_dict())
    alone = simulate(load_scenario("baseline", {"run.parts": 20}), keep_belts=False).summary
    assert not {"line_throughput_per_h", "line_wip_mean"} & set(alone.as_dict())
