"""Properties of any layout a user may write (docs/layout.md): buffers of any places and
either rule, stations downstream and in series at any offset and transfer, both policies, with
and without failures.  Parts are conserved per station and for the line; no part is set down
twice; a buffer never holds more than its places; a series station never receives a part before
the station feeding it set it down; and two fixed-cycle stations in series, the downstream
cycle no longer than the upstream's, lose nothing downstream."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cell.scenario.schema import load_scenario
from cell.sim.simulation import simulate

EXPON = {"distribution": "expon", "params": {"scale": 900.0}}
FAILURES = {"robot": {"time_to_failure": EXPON, "time_to_repair":
                      {"distribution": "expon", "params": {"scale": 60.0}}}}

buffers = st.one_of(st.none(), st.builds(
    lambda places, rule, pitch: {"places": places, "when_full": rule, "pitch_in": pitch},
    st.integers(0, 3), st.sampled_from(["ride_off", "hold_feeder"]), st.floats(2.0, 6.0)))
policies = st.sampled_from(["adaptive", "non-adaptive"])


@st.composite
def layouts(draw):  # noqa: ANN001, ANN201
    stations = []
    for i in range(draw(st.integers(0, 2))):
        placement = draw(st.sampled_from(["downstream", "series"]))
        entry = {"name": f"s{i}", "placement": placement,
                 "controller": {"policy": draw(policies)}}
        if placement == "downstream":
            entry["offset_in"] = draw(st.floats(2.5, 80.0))
        else:
            entry["transfer_in"] = draw(st.floats(1.0, 120.0))
        b = draw(buffers)
        if b is not None:
            entry["buffer"] = b
        if draw(st.booleans()):
            entry["failures"] = FAILURES
        stations.append(entry)
    sets = {"run.parts": 60, "run.seed": draw(st.integers(0, 10_000)),
            "controller.policy": draw(policies),
            "arrivals": {"distribution": "expon", "params": {"loc": 0.0,
                                                             "scale": draw(st.floats(12.0, 40.0))}}}
    b = draw(buffers)
    if b is not None:
        sets["buffer"] = b
    if stations:
        sets["stations"] = stations
    if draw(st.booleans()):
        sets["failures"] = FAILURES
    return sets


def _feeders(stations: list[dict]) -> dict[int, tuple[str, int]]:
    """Station i (1 …) -> (its placement, the station that feeds it)."""
    out, head = {}, 0
    for i, s in enumerate(stations, start=1):
        if s["placement"] == "downstream":
            out[i] = ("downstream", i - 1)
        else:
            out[i] = ("series", head)
            head = i
    return out


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(layouts())
def test_any_layout_conserves_parts_and_keeps_its_rules(sets):
    if "buffer" not in sets and "stations" not in sets:
        sets["buffer"] = {"places": 0}
    s = load_scenario("baseline", sets)
    result = simulate(s, keep_belts=False)
    r, rows, line = result.summary, result.station_rows, result.line
    # the line: every part arrived is delivered, lost or still in the cell (none: it ran out)
    assert r.parts_arrived == r.parts_delivered + r.parts_missed + r.parts_scrapped + r.parts_in_cell
    assert r.parts_in_cell == 0
    parts = result.parts
    assert sorted(parts.part) == list(range(1, r.parts_arrived + 1))  # each part one row
    feeds = _feeders(sets.get("stations", []))
    feeding = {f for placement, f in feeds.values() if placement == "series"}
    terminal = [i for i in range(len(rows)) if i not in feeding]
    # nothing set down twice: the line delivers what its last stations set down, once each
    assert sum(rows[i].parts_delivered for i in terminal) == r.parts_delivered
    for i, row in enumerate(rows):
        assert row.parts_in == row.parts_delivered + row.parts_lost  # per station
        assert row.parts_lost == row.lost_busy + row.lost_full + row.lost_down
        places = (sets.get("buffer") or {}).get("places", 0) if i == 0 else \
            (sets["stations"][i - 1].get("buffer") or sets.get("buffer") or {}).get("places", 0)
        assert row.buffer_max <= places
        rule = (sets.get("buffer") or {}) if i == 0 else \
            (sets["stations"][i - 1].get("buffer") or sets.get("buffer") or {})
        if rule.get("when_full") == "hold_feeder":
            assert row.lost_full == 0  # parts stand behind a full buffer: none is lost to it
        assert 0.0 <= row.busy_fraction <= 1.0 + 1e-9
        picked = line.logs[i].column("picked")
        assert np.unique(line.logs[i].column("part")[picked == 1]).size == \
            int(np.count_nonzero(picked))  # each part picked here once
    for i, (placement, f) in feeds.items():
        if placement != "series":  # what it lets go rides on (what it scraps does not)
            assert rows[f].parts_lost - rows[f].lost_down <= rows[i].parts_in <= rows[f].parts_lost
            continue
        assert rows[i].parts_in == rows[f].parts_delivered
        came = dict(zip(line.logs[i].column("part"), line.logs[i].column("arrival")))
        left = dict(zip(line.logs[f].column("part"), line.logs[f].column("left")))
        assert all(came[p] >= left[p] for p in came)  # never before it was set down upstream


@settings(max_examples=10, deadline=None)
@given(st.floats(20.1, 24.0), st.floats(0.0, 1.0), st.floats(1.0, 120.0),
       st.integers(0, 10_000))
def test_a_slower_station_feeding_a_faster_one_in_series_loses_nothing_downstream(
        upstream_s, share, transfer, seed):
    downstream_s = 20.1 + share * (upstream_s - 20.1)
    s = load_scenario("baseline", {
        "run.parts": 80, "run.seed": seed, "controller.policy": "non-adaptive",
        "controller.ideal_cycle_s": upstream_s,
        "arrivals": {"distribution": "expon", "params": {"loc": 0.0, "scale": 15.0}},
        "stations": [{"name": "next", "placement": "series", "transfer_in": transfer,
                      "controller": {"policy": "non-adaptive", "ideal_cycle_s": downstream_s}}]})
    rows = simulate(s, keep_parts=False, keep_belts=False).station_rows
    assert rows[0].parts_lost > 0  # the upstream station was pressed
    assert rows[1].parts_in == rows[0].parts_delivered and rows[1].parts_lost == 0
