"""OEE as plants define it (ISO 22400-2) against independent facts:

* the waterfall: OEE and the five losses, each a share of the planned busy time, sum to 1
  under failures, wear of none, maintenance and both policies (hypothesis), and each piece is
  what failures.csv, states.csv and parts.csv say it is;
* the robot up (not down) over the planned busy time follows MTBF / (MTBF + MTTR) on the
  calendar clock, maintenance taken out of the planned time (an alternating renewal process);
* a fixed-cycle robot whose parts come exactly one cycle apart is never starved after its
  first part reaches B, and its performance is the nominal cycle × parts / its motion;
* without failures or maintenance nothing is downtime and nothing blocks the robot.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

from cell.scenario.schema import load_scenario
from cell.sim.oee import LOSSES
from cell.sim.simulation import simulate

MTBF_S, MTTR_S = 1000.0, 250.0
MAINTENANCE = {"every_h": 2.0, "duration_min": 10.0}
RARE_PARTS = {"arrivals": {"distribution": "expon", "params": {"loc": 0.0, "scale": 20000.0}}}


def expon(scale: float) -> dict:
    return {"distribution": "expon", "params": {"scale": scale}}


def span_sum(spans) -> float:
    return float(sum(b - a for a, b in spans))


def overlap(a: list[tuple[float, float]], b: list[tuple[float, float]]) -> float:
    """Length of the intersection of two sets of disjoint intervals."""
    return float(sum(max(0.0, min(y1, y2) - max(x1, x2)) for x1, y1 in a for x2, y2 in b))


def assert_waterfall(res, cycle_s: float) -> None:
    """The waterfall's invariants and each piece against the run's own files."""
    r = res.summary
    end, stops = r.sim_end_s, res.stops()
    shares = [getattr(r, name) for name in LOSSES]
    assert r.oee + sum(shares) == pytest.approx(1.0, abs=1e-9)
    assert r.availability == pytest.approx(
        1.0 - r.loss_downtime - r.loss_starved - r.loss_blocked, abs=1e-9)
    assert min(r.loss_downtime, r.loss_starved, r.loss_blocked) >= 0.0
    maint = [(s.from_s, s.to_s) for s in stops if s.cause == "maintenance"]
    assert r.planned_time_s == pytest.approx(end - span_sum(maint), abs=1e-6)
    down = [(s.from_s, s.to_s) for s in stops
            if s.equipment == "robot" and s.cause != "maintenance"]
    assert r.loss_downtime * r.planned_time_s == pytest.approx(span_sum(down), abs=1e-6)
    parts = res.parts
    set_down = np.isfinite(parts["touchdown_s"].to_numpy())
    scrapped = parts["limits"].str.contains("scrapped").to_numpy()
    produced = int(set_down.sum() + scrapped.sum())
    good = int(set_down.sum())  # quality.rule: set_down (the default)
    assert r.oee == pytest.approx(cycle_s * good / r.planned_time_s, rel=1e-9)
    assert r.quality == pytest.approx(good / produced)
    assert r.loss_quality == pytest.approx(cycle_s * (produced - good) / r.planned_time_s,
                                           abs=1e-12)
    if stops:  # blocked: the robot up and still while the output belt stood (states.csv)
        spans = res.state_spans()
        still = [(s.from_s, s.to_s) for s in spans
                 if s.equipment == "robot" and s.state in ("waiting", "idle")]
        belt_down = [(s.from_s, s.to_s) for s in spans
                     if s.equipment == "output_belt" and s.state == "down"]
        assert r.loss_blocked * r.planned_time_s == pytest.approx(overlap(still, belt_down),
                                                                  abs=1e-6)


@settings(max_examples=12, deadline=None)
@given(policy=st.sampled_from(["adaptive", "non-adaptive"]),
       mtbf=st.floats(300.0, 3000.0), mttr=st.floats(20.0, 400.0),
       clock=st.sampled_from(["operating", "calendar"]),
       scrap=st.booleans(), belts=st.booleans(), maintenance=st.booleans(),
       seed=st.integers(0, 2**16))
def test_oee_and_its_losses_sum_to_the_planned_time(policy, mtbf, mttr, clock, scrap, belts,
                                                    maintenance, seed):
    failures: dict = {"robot": {"time_to_failure": expon(mtbf), "time_to_repair": expon(mttr),
                                "clock": clock, "part_in_hand": "scrap" if scrap else "finish"}}
    if belts:
        for belt in ("input_belt", "output_belt"):
            failures[belt] = {"time_to_failure": expon(2 * mtbf), "time_to_repair": expon(mttr)}
    if maintenance:
        failures["maintenance"] = {"every_h": 0.25, "duration_min": 3.0}
    s = load_scenario("baseline", {"controller.policy": policy, "run.hours": 0.75,
                                   "run.seed": seed, "failures": failures})
    res = simulate(s)
    assert_waterfall(res, res.summary.nominal_cycle_s)


@pytest.fixture(scope="module")
def rare_runs():
    """Six long runs of rare parts: the robot fails on the calendar clock (exponential up and
    repair times), stops for planned maintenance, and its output belt fails too."""
    failures = {"robot": {"time_to_failure": expon(MTBF_S), "time_to_repair": expon(MTTR_S),
                          "clock": "calendar"},
                "output_belt": {"time_to_failure": expon(4 * MTBF_S),
                                "time_to_repair": expon(MTTR_S)},
                "maintenance": MAINTENANCE}
    return [simulate(load_scenario("baseline", {**RARE_PARTS, "run.hours": 150.0,
                                                "failures": failures, "run.seed": seed}))
            for seed in range(6)]


def test_the_robot_is_up_for_mtbf_over_mtbf_plus_mttr_of_the_planned_time(rare_runs):
    """Availability leaves out starving and blocking too; with them added back (1 −
    loss_downtime) it is the alternating renewal process's MTBF / (MTBF + MTTR), over the
    planned busy time: the maintenance is neither up nor down."""
    up = [r.summary.availability + r.summary.loss_starved + r.summary.loss_blocked
          for r in rare_runs]
    x = np.asarray(up)
    half = stats.t.ppf(0.995, x.size - 1) * x.std(ddof=1) / math.sqrt(x.size)
    assert abs(x.mean() - MTBF_S / (MTBF_S + MTTR_S)) <= half, (x.mean(), half)
    assert half < 0.02  # narrow enough to mean something
    for res in rare_runs:
        r = res.summary
        assert r.robot_failures > 300 and r.planned_time_s < r.sim_end_s - 70 * 600.0
        assert r.loss_blocked > 0 and r.loss_starved > r.availability  # parts are rare
        assert_waterfall(res, r.nominal_cycle_s)


def test_a_fixed_cycle_robot_fed_every_cycle_starves_only_before_its_first_part(tmp_path: Path):
    """Parts exactly one fixed cycle apart: after the first reaches B the robot is never
    still, so the starved time is that first part's arrival at B, nothing is down or blocked,
    and performance is the nominal cycle × parts delivered over its motion (parts.csv)."""
    cycle = 22.5872
    (tmp_path / "trace.csv").write_text("interarrival_s\n" + f"{cycle}\n" * 400)
    (tmp_path / "s.yaml").write_text(
        "controller: {policy: non-adaptive, nominal_cycle_s: 22.5872, ideal_cycle_s: 22.5872}\n"
        "arrivals: {trace_csv: trace.csv}\nrun: {parts: 300}\n")
    res = simulate(load_scenario(tmp_path / "s.yaml"))
    r, parts = res.summary, res.parts
    assert r.parts_delivered == 300 and r.planned_time_s == r.sim_end_s
    first_at_b = parts["at_bot_s"].iloc[0]
    assert r.loss_starved == pytest.approx(first_at_b / r.sim_end_s, abs=1e-12)
    assert r.availability == pytest.approx(1.0 - first_at_b / r.sim_end_s, abs=1e-12)
    assert r.loss_downtime == 0.0 and r.loss_blocked == 0.0 and r.quality == 1.0
    start = parts["at_bot_s"].to_numpy()
    motion = np.minimum(start + parts["motion_cycle_s"].to_numpy(), r.sim_end_s) - start
    assert r.performance == pytest.approx(cycle * 300 / motion.sum(), rel=1e-12)
    assert_waterfall(res, cycle)


@pytest.mark.parametrize("name", ["baseline", "non_adaptive"])
def test_without_failures_nothing_is_downtime_and_nothing_blocks(name):
    res = simulate(load_scenario(name, {"run.parts": 200}))
    r = res.summary
    assert r.loss_downtime == 0.0 and r.loss_blocked == 0.0
    assert r.planned_time_s == r.sim_end_s
    assert r.availability == pytest.approx(r.robot_busy_fraction, abs=1e-12)
    assert_waterfall(res, r.nominal_cycle_s)


def test_the_spacing_rule_counts_parts_set_down_off_spacing_as_not_good():
    base = {"controller.ideal_cycle_s": 21.0, "controller.policy": "non-adaptive",
            "run.parts": 200}
    plain = simulate(load_scenario("baseline", base), keep_parts=False).summary
    strict = simulate(load_scenario("baseline", {**base, "quality.rule": "spacing"}),
                      keep_parts=False).summary
    assert strict.spacing_outside_tol > 0 and plain.quality == 1.0
    assert strict.quality == pytest.approx(1 - strict.spacing_outside_tol
                                           / strict.parts_delivered)
    assert strict.loss_quality > 0 and strict.oee < plain.oee
    assert strict.availability == plain.availability  # the same run, counted differently
