"""A layout on a shift calendar (docs/layout.md, "Stations"): the calendar stands every station.
No station's robot picks or sets down a part off shift, every station's equipment's states tile
the run with ``off_shift`` exactly where the calendar (rebuilt with datetime in
tests/sim/test_calendar.py) has no work, parts are conserved per station, and a later station's
failures on the ``working`` clock are in failures.csv's rows under its name."""

from __future__ import annotations

import numpy as np
import pytest

from cell.scenario.schema import load_scenario
from cell.sim.simulation import simulate
from tests.sim.test_calendar import TWO_SHIFTS, inside, working_spans

NEXT_FAILS = {"robot": {"time_to_failure": {"distribution": "expon", "mean_h": 1.0},
                        "time_to_repair": {"distribution": "expon", "mean_h": 0.1},
                        "clock": "working"}}


@pytest.fixture(scope="module")
def line_run():
    s = load_scenario("baseline", {
        "calendar": TWO_SHIFTS, "run.parts": 2000, "run.seed": 11,
        "arrivals": {"distribution": "expon", "params": {"loc": 0.0, "scale": 30.0}},
        "buffer": {"places": 2},
        "stations": [{"name": "next", "placement": "series", "transfer_in": 60,
                      "controller": {"policy": "non-adaptive", "ideal_cycle_s": 20.5},
                      "failures": NEXT_FAILS},
                     {"name": "catcher", "placement": "downstream", "offset_in": 40}]})
    return simulate(s, keep_belts=False)


def test_no_station_picks_or_sets_down_off_shift(line_run):
    end = line_run.summary.sim_end_s
    work = working_spans(TWO_SHIFTS, end)
    assert end > 24 * 3600  # the run crossed a night off shift, and two breaks
    for log in line_run.line.logs:
        picked = log.column("picked") == 1
        for name in ("at_bot", "left"):
            t = log.column(name)[picked]
            assert t.size and inside(t, work).all()


def test_every_stations_states_tile_the_run_off_shift_where_the_calendar_says(line_run):
    end = line_run.summary.sim_end_s
    work = working_spans(TWO_SHIFTS, end)
    off = sum(b - a for a, b in zip([0.0] + [e for _, e in work], [s for s, _ in work] + [end]))
    spans = line_run.state_spans()
    assert {s.station for s in spans} == {"first", "next", "catcher"}
    for station in ("first", "next", "catcher"):
        for equipment in ("robot", "input_belt", "output_belt"):
            rows = [s for s in spans if (s.station, s.equipment) == (station, equipment)]
            edges = np.array([(s.from_s, s.to_s) for s in rows])
            assert edges[0, 0] == 0.0 and edges[-1, 1] == pytest.approx(end)
            assert (edges[1:, 0] == edges[:-1, 1]).all()
            shown = sum(s.to_s - s.from_s for s in rows if s.state == "off_shift")
            assert shown == pytest.approx(off, abs=1e-6)


def test_parts_are_conserved_per_station_and_the_later_failures_are_named(line_run):
    r, rows = line_run.summary, line_run.station_rows
    for row in rows:
        assert row.parts_in == row.parts_delivered + row.parts_lost  # the run ran out
    assert rows[1].parts_in == rows[0].parts_delivered and rows[2].parts_in <= rows[1].parts_lost
    assert r.parts_delivered == rows[1].parts_delivered + rows[2].parts_delivered
    stops = line_run.stops()
    assert stops and {s.station for s in stops} == {"next"}
    assert rows[1].down_fraction > 0 and rows[0].down_fraction == rows[2].down_fraction == 0
