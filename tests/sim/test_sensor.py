"""The look-ahead sensor (cell/sim/sensor.py, docs/model.md "The look-ahead"): with
``lookahead: sensor`` nothing the controller decides depends on a part the sensor could
not yet have reported; with ``ideal`` it does (the thesis's idealisation)."""

from __future__ import annotations

from unittest import mock

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cell.sim.horizon
from cell.scenario.schema import Scenario
from cell.sim.simulation import SimResult, simulate
from tests.hostile.harness import cli, refused, tree

#: The accounting's reading of a part's *next* inter-arrival time: not a decision.
NEXT_ARRIVAL = ("ip_wallclock", "ip_thesis")


def run_trace(s: Scenario, times: list[float], seed: int = 11) -> SimResult:
    """A run whose inter-arrival times are ``times`` (run.parts + 1 of them)."""
    def draws(_arrivals: object, n: int, *_: object) -> np.ndarray:
        assert n == len(times)
        return np.asarray(times, dtype=float)

    with mock.patch.object(cell.sim.horizon, "interarrival_times", draws):
        return simulate(s, seed=seed)


def decided_before(r: SimResult, k: int, t_star: float) -> tuple[pd.DataFrame, list]:
    """Parts 1..k that reached B before ``t_star`` (their rows, the next-arrival readings of
    part k blanked) and every belt change that took effect before ``t_star``."""
    p = r.parts
    rows = p[(p["part"] <= k) & (p["at_bot_s"] < t_star)].copy()
    rows.loc[rows["part"] == k, list(NEXT_ARRIVAL)] = np.nan
    return rows.reset_index(drop=True), [c for c in r.belt_changes if c.from_s < t_star]


def same_before(s: Scenario, a: list[float], b: list[float], k: int) -> bool:
    """Whether traces ``a`` and ``b`` (equal in their first k times) give the same rows and
    belt changes up to the earliest instant the sensor could report part k + 1."""
    assert a[:k] == b[:k]
    come = min(sum(a[:k + 1]), sum(b[:k + 1]))
    t_star = come + s.sensor.latency_s
    ra, rb = run_trace(s, a), run_trace(s, b)
    rows_a, belts_a = decided_before(ra, k, t_star)
    rows_b, belts_b = decided_before(rb, k, t_star)
    return len(rows_a) > 0 and rows_a.equals(rows_b) and belts_a == belts_b


@pytest.fixture(scope="module")
def sensing(thesis_cell: Scenario) -> Scenario:
    return thesis_cell.with_overrides({"run.parts": 12, "sensor.lookahead": "sensor"})


# Part 6 comes 50 or 60 s after part 5: either way after part 5 reaches B (45 s of belt).
SLOW = [22.6] * 5 + [50.0] + [22.6] * 7
SLOWER = [22.6] * 5 + [60.0] + [22.6] * 7


def test_a_sensor_decides_nothing_from_a_part_it_has_not_seen(sensing: Scenario) -> None:
    assert same_before(sensing, SLOW, SLOWER, 5)
    noisy = sensing.with_overrides({"sensor.noise_sd_in": 1.0, "sensor.latency_s": 2.0,
                                    "sensor.miss_probability": 0.2, "sensor.position_in": 80.0})
    assert same_before(noisy, SLOW, SLOWER, 5)


def test_the_ideal_look_ahead_does_know_the_future(sensing: Scenario) -> None:
    """The same test fails for the thesis's look-ahead: part 5's plan reads when part 6 will
    be dropped, which no sensor could have reported yet."""
    assert not same_before(sensing.with_overrides({"sensor.lookahead": "ideal"}), SLOW, SLOWER, 5)


@settings(max_examples=20, deadline=None)
@given(st.data())
def test_no_foreknowledge_over_random_traces_and_sensors(thesis_cell: Scenario, data: st.DataObject) -> None:
    k = data.draw(st.integers(2, 8), label="k")
    n = k + 6
    gap = st.floats(5.0, 70.0, allow_nan=False)
    head = data.draw(st.lists(gap, min_size=k, max_size=k), label="head")
    tail_a = data.draw(st.lists(gap, min_size=n + 1 - k, max_size=n + 1 - k), label="tail a")
    tail_b = data.draw(st.lists(gap, min_size=n + 1 - k, max_size=n + 1 - k), label="tail b")
    s = thesis_cell.with_overrides({
        "run.parts": n, "sensor.lookahead": "sensor",
        "sensor.position_in": data.draw(st.floats(0.0, 135.0), label="position"),
        "sensor.noise_sd_in": data.draw(st.sampled_from([0.0, 0.3, 2.0]), label="noise"),
        "sensor.latency_s": data.draw(st.sampled_from([0.0, 0.5, 4.0]), label="latency"),
        "sensor.miss_probability": data.draw(st.sampled_from([0.0, 0.3]), label="miss")})
    a, b = head + tail_a, head + tail_b
    come = min(sum(a[:k + 1]), sum(b[:k + 1]))
    t_star = come + s.sensor.latency_s
    rows_a, belts_a = decided_before(run_trace(s, a), k, t_star)
    rows_b, belts_b = decided_before(run_trace(s, b), k, t_star)
    pd.testing.assert_frame_equal(rows_a, rows_b)
    assert belts_a == belts_b


def test_a_perfect_sensor_at_the_drop_point_sees_what_the_feeder_dropped(thesis_cell: Scenario) -> None:
    """On the thesis's arrivals the next part is nearly always on the belt when the controller
    looks (L = 135.5 in is 45 s of belt): a perfect sensor there loses no part either, and its
    throughput is the ideal look-ahead's to within 1 %."""
    s = thesis_cell.with_overrides({"run.parts": 300})
    ideal = simulate(s, seed=4).summary
    seen = simulate(s.with_overrides({"sensor.lookahead": "sensor"}), seed=4).summary
    assert ideal.parts_missed == seen.parts_missed == 0
    assert seen.parts_per_hr_wallclock == pytest.approx(ideal.parts_per_hr_wallclock, rel=0.01)


def test_a_blind_controller_runs_the_nominal_cycle(thesis_cell: Scenario) -> None:
    """Nothing reported (every part missed): each cycle is the nominal one, the belts' speeds
    untouched at the input: the robot is the fixed-cycle robot at the nominal cycle (§6.3)."""
    s = thesis_cell.with_overrides({"run.parts": 200, "sensor.lookahead": "sensor",
                                    "sensor.miss_probability": 1.0})
    blind = simulate(s, seed=2)
    fixed = simulate(s.with_overrides({"controller.policy": "non-adaptive"}), seed=2)
    assert blind.summary.parts_missed == fixed.summary.parts_missed > 0
    np.testing.assert_allclose(blind.parts["motion_cycle_s"].dropna(), 22.5872, rtol=1e-12)
    assert {v for _, v in blind.belts["input"]} == {3.0}


def test_sensor_down_reports_nothing_even_ideal(thesis_cell: Scenario) -> None:
    """h21's failure process sets View.sensor_up False: next_part is None, ideal included
    (the view of a run whose sensor can fail)."""
    from cell.sim.assembly import assemble
    from cell.sim.controller import View

    cell_ = assemble(thesis_cell)
    view = View.__new__(View)
    view.sensor_up, view.now, view.part, view.n, view.fed_s = False, 0.0, 0, 3, [1.0, 2.0, 3.0]
    assert view.next_part(1.0, 3.0) is None
    assert cell_.k.lookahead_margin_s == 0.0


def test_the_noise_and_misses_have_streams_of_their_own(thesis_cell: Scenario) -> None:
    """The sensor draws from its own streams: the arrivals are the same with or without it
    (common random numbers), and the fixed-cycle robot, which has no look-ahead, is unmoved."""
    s = thesis_cell.with_overrides({"run.parts": 100, "controller.policy": "non-adaptive"})
    plain = simulate(s, seed=9)
    noisy = simulate(s.with_overrides({"sensor.lookahead": "sensor", "sensor.noise_sd_in": 3.0,
                                       "sensor.miss_probability": 0.5}), seed=9)
    assert plain.parts.equals(noisy.parts)


@pytest.mark.parametrize("key, value, words", [
    ("sensor.noise_sd_in", "-0.5", ("must be at least 0",)),
    ("sensor.latency_s", "-1", ("must be at least 0",)),
    ("sensor.position_in", "-2", ("must be at least 0",)),
    ("sensor.position_in", "500", ("beyond the feeder's drop point",)),
    ("sensor.miss_probability", "1.5", ("must be at most 1",)),
    ("sensor.miss_probability", "-0.1", ("must be at least 0",)),
    ("sensor.lookahead", "psychic", ("ideal", "sensor")),
])
def test_bad_sensor_settings_are_refused(tmp_path, key: str, value: str, words: tuple[str, ...]) -> None:
    scenario = tmp_path / "s.yaml"
    scenario.write_text(f"sensor:\n  {key.split('.')[1]}: {value}\n")
    out = tmp_path / "out"
    line = refused(cli("run", scenario, "--out", out), str(scenario), key, value, *words,
                   nothing_in=out, before=None)
    assert tree(out) is None, line
