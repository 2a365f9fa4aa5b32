"""A layout's failures and states in the outputs (docs/layout.md, "Measures"): failures.csv and
states.csv hold every station's rows, each naming its station as stations.csv does, and are
written when any station can fail; each station's states tile the run, its downtime in
states.csv is its repairs in failures.csv and its ``down_fraction`` in stations.csv; the
summary's time shares are the first station's robot's."""

from __future__ import annotations

import contextlib
import io

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cell.cli.main import main
from cell.scenario.schema import load_scenario
from cell.sim.records import STATE_COLUMNS, STOP_COLUMNS
from cell.sim.simulation import simulate

SECOND_FAILS = """\
name: second_fails
run: {hours: 3, seed: 7}
costs: {repair: 100, downtime_per_h: 60}   # nothing else costs
energy: {arm: none}                         # every state's default power
arrivals: {distribution: expon, params: {loc: 0.0, scale: 21.0}}
stations:
  - name: next
    placement: series
    transfer_in: 60
    controller: {policy: non-adaptive, ideal_cycle_s: 20.5}
    failures:
      robot: {time_to_failure: {distribution: weibull_min, mean_h: 0.5, shape: 1.5},
              time_to_repair: {distribution: lognorm, mean_h: 0.05, cv: 0.8}}
      output_belt: {time_to_failure: {distribution: weibull_min, mean_h: 1, shape: 1.2},
                    time_to_repair: {distribution: expon, mean_s: 120}}
"""


@pytest.fixture(scope="module")
def second_fails(tmp_path_factory: pytest.TempPathFactory) -> dict[str, pd.DataFrame]:
    """``cell run`` (in-process) of a two-station line whose only failing station is the
    second: its output files, read back."""
    where = tmp_path_factory.mktemp("second_fails")
    (where / "line.yaml").write_text(SECOND_FAILS)
    said = io.StringIO()
    with contextlib.redirect_stdout(said), contextlib.redirect_stderr(io.StringIO()):
        assert main(["run", str(where / "line.yaml"), "--out", str(where / "out")]) == 0
    return {"stdout": said.getvalue(), **{name: pd.read_csv(where / "out" / f"{name}.csv")
                                          for name in ("failures", "states", "stations", "summary")}}


def test_cell_run_prints_each_stations_downtime(second_fails):
    """The printed stops line is the first station's; the next line gives every station's
    share of the run down, as stations.csv has it."""
    line = next(x for x in second_fails["stdout"].splitlines() if x.startswith("down, share"))
    shown = dict(part.rsplit(" ", 1) for part in line.split(": ", 1)[1].split(", "))
    stations = second_fails["stations"]
    assert list(shown) == list(stations.station)
    np.testing.assert_allclose([float(v) for v in shown.values()], stations.down_fraction, atol=5e-4)
    assert float(shown["next"]) > 0 == float(shown["first"])


def test_the_second_stations_failures_are_in_failures_csv_named_as_in_stations_csv(second_fails):
    stops, stations = second_fails["failures"], second_fails["stations"]
    assert list(stops.columns) == [*STOP_COLUMNS, "station"]
    assert list(stations.station) == ["first", "next"]
    assert len(stops) > 0 and set(stops.station) == {"next"}  # the first never fails
    assert set(stops.equipment) == {"robot", "output_belt"}
    assert (stops.from_s.diff().dropna() >= 0).all()  # in order of start


def test_each_stations_states_tile_the_run(second_fails):
    states, end = second_fails["states"], second_fails["summary"].sim_end_s.iloc[0]
    assert list(states.columns) == [*STATE_COLUMNS, "station"]
    assert set(states.station) == {"first", "next"}
    for _, rows in states.groupby(["station", "equipment"], sort=False):
        assert rows.from_s.iloc[0] == 0.0 and rows.to_s.iloc[-1] == pytest.approx(end)
        assert (rows.from_s.to_numpy()[1:] == rows.to_s.to_numpy()[:-1]).all()
        assert (rows.to_s - rows.from_s).sum() == pytest.approx(end)
    for station in ("first", "next"):
        assert set(states[states.station == station].equipment) == {
            "robot", "input_belt", "output_belt"}


def test_a_stations_downtime_in_states_csv_is_its_repairs_in_failures_csv(second_fails):
    states, stops = second_fails["states"], second_fails["failures"]
    stations, end = second_fails["stations"], second_fails["summary"].sim_end_s.iloc[0]
    for station in ("first", "next"):
        for equipment in ("robot", "output_belt"):
            down = states[(states.station == station) & (states.equipment == equipment)
                          & (states.state == "down")]
            repairs = stops[(stops.station == station) & (stops.equipment == equipment)]
            assert (down.to_s - down.from_s).sum() == pytest.approx(
                (repairs.to_s - repairs.from_s).sum(), abs=1e-6)
        robot_down = states[(states.station == station) & (states.equipment == "robot")
                            & (states.state == "down")]
        row = stations[stations.station == station].iloc[0]
        assert row.down_fraction == pytest.approx((robot_down.to_s - robot_down.from_s).sum() / end,
                                                  abs=1e-9)
    assert stations.down_fraction.iloc[1] > 0


def test_the_summarys_time_shares_are_the_first_stations_robots(second_fails):
    summary, stations = second_fails["summary"].iloc[0], second_fails["stations"]
    first = stations[stations.station == "first"].iloc[0]
    assert summary.robot_down_fraction == 0 and summary.loss_downtime == 0  # the first never fails
    assert summary.robot_busy_fraction == pytest.approx(first.busy_fraction, abs=1e-9)
    assert summary.availability == pytest.approx(first.busy_fraction, abs=1e-9)


def test_the_lines_cost_counts_every_stations_repairs_and_robot_downtime(second_fails):
    summary, stops = second_fails["summary"].iloc[0], second_fails["failures"]
    states = second_fails["states"]
    robots_down = states[(states.equipment == "robot") & (states.state == "down")]
    down_h = (robots_down.to_s - robots_down.from_s).sum() / 3600.0
    hours = summary.sim_end_s / 3600.0
    assert summary.cost_per_h * hours == pytest.approx(100 * len(stops) + 60 * down_h, rel=1e-8)


def test_the_lines_energy_is_the_sum_over_every_stations_states(second_fails):
    from cell.scenario.energy_sections import EnergySettings

    power, states = EnergySettings().power, second_fails["states"]
    joules = sum(power(e, state) * (b - a)
                 for e, state, a, b in zip(states.equipment, states.state, states.from_s, states.to_s))
    assert second_fails["summary"].energy_kwh.iloc[0] * 3.6e6 == pytest.approx(joules, rel=1e-9)


FAILS = {"robot": {"time_to_failure": {"distribution": "expon", "params": {"scale": 600.0}},
                   "time_to_repair": {"distribution": "expon", "params": {"scale": 60.0}}},
         "input_belt": {"time_to_failure": {"distribution": "expon", "params": {"scale": 900.0}},
                        "time_to_repair": {"distribution": "expon", "params": {"scale": 60.0}}}}


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.sampled_from(["downstream", "series"]), min_size=1, max_size=2),
       st.data(), st.integers(0, 10_000))
def test_parts_are_conserved_per_station_with_failures_on_any_station(placements, data, seed):
    failing = data.draw(st.integers(0, len(placements)), label="failing station")
    stations = [{"name": f"s{i}", "placement": p, "offset_in": 40.0} if p == "downstream" else
                {"name": f"s{i}", "placement": p, "transfer_in": 60.0}
                for i, p in enumerate(placements, start=1)]
    sets: dict = {"run.parts": 60, "run.seed": seed, "stations": stations,
                  "arrivals": {"distribution": "expon", "params": {"loc": 0.0, "scale": 18.0}}}
    if failing:
        stations[failing - 1]["failures"] = FAILS
    else:
        sets["failures"] = FAILS
    result = simulate(load_scenario("baseline", sets), keep_belts=False)
    names = ["first", *(s["name"] for s in stations)]
    for row in result.station_rows:
        assert row.parts_in == row.parts_delivered + row.parts_lost  # the run ran out
    stops = result.stops()
    # the scenario's own failures: every station's, as its other sections (docs/layout.md)
    assert {s.station for s in stops} <= (set(names) if failing == 0 else {names[failing]})
    end = result.summary.sim_end_s
    spans = result.state_spans()
    for name in names:
        for equipment in ("robot", "input_belt", "output_belt"):
            rows = [(s.from_s, s.to_s) for s in spans if (s.station, s.equipment) == (name, equipment)]
            ends = np.asarray(rows)
            assert ends[0, 0] == 0.0 and ends[-1, 1] == pytest.approx(end)
            assert (ends[1:, 0] == ends[:-1, 1]).all()


def test_a_run_without_layout_names_no_station():
    from cell.sim.sim_result import named_columns

    result = simulate(load_scenario("baseline", {"run.parts": 100, "failures": FAILS}),
                      keep_belts=False)
    assert result.line is None and named_columns(result, STOP_COLUMNS) == STOP_COLUMNS
    assert len(result.stops()) > 0 and {s.station for s in result.stops()} == {None}
    assert {s.station for s in result.state_spans()} == {None}
