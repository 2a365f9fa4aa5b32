"""Failures in the simulated cell against closed forms (SPEC §10) and invariants.

* one machine alternating up and down, failure clock on calendar time: the long-run share of
  time down is MTTR / (MTBF + MTTR) (an alternating renewal process);
* on the operating clock, with the robot working a share b of its up time:
  A = (MTBF_op / b) / (MTBF_op / b + MTTR);
* two machines sharing one repair crew (machine-repairman, exponential): p0 : p1 : p2 =
  1 : 2λ/μ : 2(λ/μ)²;
* parts conserved and belts physical under any failures (hypothesis); with failures that
  never come, the same parts as without failures, and no more events a part.

Closed-form runs are long in simulated time but cheap: the parts come rarely (an
inter-arrival of hours), so each costs the failure events and a few parts.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

from cell.bench.throughput import events_per_part
from cell.scenario.schema import load_scenario
from cell.sim.simulation import simulate


def expon(scale: float) -> dict:
    return {"distribution": "expon", "params": {"scale": scale}}


def ci(values: list[float], level: float = 0.99) -> tuple[float, float]:
    """Student-t interval of the mean over replications."""
    x = np.asarray(values)
    half = stats.t.ppf(0.5 + level / 2, x.size - 1) * x.std(ddof=1) / math.sqrt(x.size)
    return x.mean() - half, x.mean() + half


RARE_PARTS = {"arrivals": {"distribution": "expon", "params": {"loc": 0.0, "scale": 20000.0}}}


def _rare(failures: dict, hours: float, policy: str = "adaptive") -> dict:
    return {**RARE_PARTS, "run.hours": hours, "failures": failures,
            "controller.policy": policy}


def down_spans(result, equipment: str) -> list[tuple[float, float]]:
    return [(s.from_s, s.to_s) for s in result.stops() if s.equipment == equipment
            and s.cause != "maintenance"]


def test_calendar_clock_down_share_is_mttr_over_mtbf_plus_mttr():
    mtbf, mttr = 1000.0, 250.0
    f = {"robot": {"time_to_failure": expon(mtbf), "time_to_repair": expon(mttr),
                   "clock": "calendar"}}
    shares = []
    for seed in range(8):
        s = load_scenario("baseline", {**_rare(f, 60.0), "run.seed": seed})
        r = simulate(s, keep_parts=False, keep_belts=False).summary
        assert r.robot_failures > 100
        shares.append(r.robot_down_fraction)
    lo, hi = ci(shares)
    assert lo <= mttr / (mtbf + mttr) <= hi, (lo, hi)
    assert hi - lo < 0.05  # the interval is narrow enough to mean something


def test_operating_clock_availability_follows_the_share_of_time_worked():
    mtbf_op, mttr = 400.0, 80.0
    f = {"robot": {"time_to_failure": expon(mtbf_op), "time_to_repair": expon(mttr),
                   "clock": "operating"}}
    predicted, observed = [], []
    for seed in range(6):
        s = load_scenario("non_adaptive", {"run.hours": 4.0, "failures": f, "run.seed": seed})
        r = simulate(s, keep_parts=False, keep_belts=False).summary
        up = 1.0 - r.robot_down_fraction
        b = r.robot_busy_fraction / up  # the share of up time the robot works
        assert 0.5 < b < 0.8  # the fixed cycle waits for a third of its parts
        predicted.append((mtbf_op / b) / (mtbf_op / b + mttr))
        observed.append(up)
    lo, hi = ci([o - p for o, p in zip(observed, predicted)])
    assert lo <= 0.0 <= hi, (lo, hi)
    # and the calendar reading would be wrong: the robot does not fail while it stands
    assert np.mean(observed) > mtbf_op / (mtbf_op + mttr) + 0.03


def test_two_machines_one_crew_match_the_machine_repairman_model():
    lam, mu = 1 / 1000.0, 1 / 500.0
    f = {"robot": {"time_to_failure": expon(1 / lam), "time_to_repair": expon(1 / mu),
                   "clock": "calendar"},
         "input_belt": {"time_to_failure": expon(1 / lam), "time_to_repair": expon(1 / mu),
                        "clock": "calendar"},
         "repair": {"crews": 1}}
    rho = lam / mu
    weights = np.array([1.0, 2 * rho, 2 * rho**2])
    expected = weights / weights.sum()
    shares = []
    for seed in range(8):
        s = load_scenario("baseline", {**_rare(f, 60.0), "run.seed": seed})
        res = simulate(s, keep_parts=False, keep_belts=False)
        horizon = res.summary.sim_end_s
        cuts = [(a, +1) for a, _ in down_spans(res, "robot") + down_spans(res, "input_belt")]
        cuts += [(b, -1) for _, b in down_spans(res, "robot") + down_spans(res, "input_belt")]
        cuts.sort()
        time_in = np.zeros(3)
        level, last = 0, 0.0
        for t, step in cuts:
            time_in[level] += t - last
            level, last = level + step, t
        time_in[level] += horizon - last
        shares.append(time_in / horizon)
    shares_arr = np.array(shares)
    for k in range(3):
        lo, hi = ci(list(shares_arr[:, k]))
        assert lo <= expected[k] <= hi, (k, lo, hi, expected[k])


def test_a_failure_waits_for_the_one_crew():
    f = {"robot": {"time_to_failure": expon(500.0), "time_to_repair": expon(500.0),
                   "clock": "calendar"},
         "output_belt": {"time_to_failure": expon(500.0), "time_to_repair": expon(500.0),
                         "clock": "calendar"},
         "repair": {"crews": 1}}
    res = simulate(load_scenario("baseline", {**_rare(f, 20.0), "arrivals.params.scale": 5000.0}),
                   keep_parts=False, keep_belts=False)
    stops = sorted(res.stops(), key=lambda s: s.from_s)
    # a failure while the other is down waits for the one crew: it is repaired after it
    both = [(a.to_s, b.to_s) for a in stops for b in stops
            if a.equipment != b.equipment and a.from_s < b.from_s < a.to_s]
    assert both, "no failure came while the other was down"
    for first_up, second_up in both:
        assert second_up > first_up


NEVER = {name: {"time_to_failure": expon(1e12), "time_to_repair": expon(60.0)}
         for name in ("robot", "input_belt", "output_belt", "sensor")}


@pytest.mark.parametrize("name", ["baseline", "non_adaptive"])
def test_failures_that_never_come_leave_every_part_as_without_failures(name):
    """One robot cycle, one belt model whatever can fail: a run whose equipment could fail
    but does not (times to failure of 30,000 years) is the run without failures, to the bit."""
    fast = simulate(load_scenario(name, {"run.parts": 120}))
    legs = simulate(load_scenario(name, {"run.parts": 120, "failures": NEVER}))
    import pandas as pd

    pd.testing.assert_frame_equal(fast.parts, legs.parts, check_exact=True)
    assert fast.summary.parts_delivered == legs.summary.parts_delivered


def test_a_stop_costs_nothing_while_nothing_stops():
    """Failure clocks (motor wear counted on the robot's) add no event to a cycle in which
    nothing fails: the SimPy events a part are those of the run without failures, within a
    few hundredths (the clocks' own and the few failures' events)."""
    wear = {"run.hours": 20.0, "wear.enabled": True}
    plain = events_per_part(load_scenario("baseline", wear))
    f = {**NEVER, "robot": {"time_to_failure": expon(1e12),
                            "time_to_repair": expon(3600.0)}}
    failing = events_per_part(load_scenario("baseline", {**wear, "failures": f}))
    assert failing <= plain + 0.05, (failing, plain)


def distributions(mean: float) -> st.SearchStrategy[dict]:
    return st.sampled_from([
        expon(mean),
        {"distribution": "weibull_min", "params": {"c": 2.0, "scale": mean}},
        {"distribution": "lognorm", "params": {"s": 0.8, "scale": mean}},
        {"distribution": "uniform", "params": {"loc": 0.0, "scale": 2 * mean}},
    ])


@st.composite
def failure_sections(draw: st.DrawFn) -> dict:
    f: dict = {}
    for name in ("robot", "input_belt", "output_belt", "sensor"):
        if draw(st.booleans()):
            f[name] = {"time_to_failure": draw(distributions(draw(st.sampled_from([60., 300.])))),
                       "time_to_repair": draw(distributions(draw(st.sampled_from([20., 120.])))),
                       "clock": draw(st.sampled_from(["operating", "calendar"]))}
    if "robot" in f:
        f["robot"]["part_in_hand"] = draw(st.sampled_from(["finish", "scrap"]))
    if draw(st.booleans()):
        f["repair"] = {"crews": draw(st.integers(1, 2))}
    if draw(st.booleans()):
        f["maintenance"] = {"every_h": 0.25, "duration_min": 2.0}
    return f


@settings(max_examples=12, deadline=None)
@given(failure_sections(), st.sampled_from(["adaptive", "non-adaptive"]),
       st.sampled_from([{"run.parts": 80}, {"run.hours": 0.5}]), st.integers(0, 3))
def test_parts_are_conserved_and_belts_physical_under_any_failures(f, policy, length, seed):
    s = load_scenario("baseline", {**length, "failures": f, "controller.policy": policy,
                                   "run.seed": seed})
    res = simulate(s)
    r = res.summary
    assert r.parts_arrived == r.parts_delivered + r.parts_missed + r.parts_scrapped + \
        r.parts_in_cell
    assert 0 <= r.parts_lost_downtime <= r.parts_missed
    if "run.parts" in length:
        assert r.parts_in_cell == 0 and r.parts_arrived == s.run.parts
    parts = res.parts
    delivered = parts[parts.touchdown_s.notna()]
    assert (delivered.touchdown_s.diff().dropna() >= 0).all()  # set down in order
    assert (parts.at_bot_s.diff().dropna() >= -1e-9).all()    # nothing overtakes on the belt
    assert (delivered.spacing_in.dropna() >= -1e-9).all()
    for belt, history in res.belt_histories().items():
        speed = history[:, 1]
        assert (speed >= 0).all()
        limit = s.belts.input_max_in_s if belt == "input" else s.belts.output_max_in_s
        assert (speed <= limit + 1e-9).all()
        assert (np.diff(history[:, 0]) >= 0).all()
    for span in res.stops():
        assert 0 <= span.from_s <= span.to_s <= r.sim_end_s + 1e-9
    shares = (r.robot_busy_fraction + r.robot_waiting_fraction + r.robot_idle_fraction
              + r.robot_down_fraction + r.robot_maintenance_fraction)
    assert shares == pytest.approx(1.0)
    assert 0 <= r.availability <= 1
    # quality is a share of the parts delivered: undefined (NaN) when none was
    assert 0 <= r.quality <= 1 if r.parts_delivered else math.isnan(r.quality)


def test_the_sensor_down_leaves_the_controller_without_look_ahead():
    f = {"sensor": {"time_to_failure": expon(1e9), "time_to_repair": expon(1.0)}}
    s = load_scenario("baseline", {"run.parts": 60, "failures": f})
    from cell.sim.controller import View

    seen: list[bool] = []
    original = View.next_part

    def spy(self, lag, v):  # noqa: ANN001, ANN202
        self.sensor_up = False  # as the sensor's failure sets it
        out = original(self, lag, v)
        seen.append(out is None)
        return out

    View.next_part = spy  # type: ignore[method-assign]
    try:
        r = simulate(s).summary
    finally:
        View.next_part = original  # type: ignore[method-assign]
    assert seen and all(seen)
    # no look-ahead: the adaptive controller runs its nominal cycle and never steers the
    # input belt for a next part (no ceiling hit, no R IV at its peak)
    assert r.limit_input_ceiling == 0 and r.limit_r4_peak == 0


@pytest.mark.parametrize("name", ["baseline", "non_adaptive"])
def test_the_shares_summed_without_failures_are_the_timelines(name, monkeypatch):
    import cell.sim.oee as oee
    import cell.sim.simulation as sim

    seen: dict = {}
    measure = oee.measure

    def grab(*args):  # noqa: ANN002, ANN202
        seen["args"] = args
        return measure(*args)

    monkeypatch.setattr(sim.oee, "measure", grab)
    simulate(load_scenario(name, {"run.parts": 400}), keep_parts=False, keep_belts=False)
    _, column, _, _, end, stops, *_ = seen["args"]
    assert stops == []  # no failures, no wear: nothing stops the cell
    fast = oee.fast_shares(column, end)
    full = oee.fractions(oee.timelines(column, None, end)["robot"], end, oee.ROBOT_STATES)
    assert fast == pytest.approx(full, abs=1e-12)
    assert sum(fast.values()) == pytest.approx(1.0)


class RIVWear:
    """A wear model's shape: one motor worn only in R IV, failing after 100 s of it; with
    ``ahead`` it tells the clock each cycle's use as the cycle starts (the wear model's way),
    else the clock counts leg by leg."""

    cause = "wear"

    def __init__(self, ahead: bool):
        self.ahead, self.told = ahead, 0

    def thresholds(self) -> list[float]:
        return [100.0]

    def renew(self, component: int) -> float:
        return 100.0

    def rates(self, leg: int) -> tuple[float, ...]:
        return (1.0,) if leg == 5 else (0.0,)

    def cycle(self, legs_s):  # noqa: ANN001, ANN201
        self.told += 1
        return (legs_s[5],) if self.ahead else None

    def cycles(self, legs_s):  # noqa: ANN001, ANN201 (the cycles the clock kept, in order)
        return np.array([self.cycle(legs) for legs in legs_s], dtype=float).reshape(-1, 1)

    def peak_rates(self) -> tuple[float, ...] | None:
        return (1.0,) if self.ahead else None  # 1 a second at most (R IV); None: not known


@pytest.mark.parametrize("ahead", [True, False])
def test_a_wear_exposure_drives_the_robots_failure_clock(monkeypatch, ahead):
    import functools

    import cell.sim.simulation as sim
    from cell.sim.failures import Downtime

    wear = RIVWear(ahead)
    monkeypatch.setattr(sim, "Downtime", functools.partial(Downtime, robot_exposure=wear))
    f = {"robot": {"time_to_failure": expon(1.0),
                   "time_to_repair": {"distribution": "uniform", "params": {"loc": 60.0,
                                                                            "scale": 1e-6}}}}
    res = simulate(load_scenario("non_adaptive", {"run.parts": 60, "failures": f}))
    first = res.stops()[0]
    assert first.cause == "wear" and first.to_s - first.from_s == pytest.approx(60.0, abs=1e-5)
    # R IV motion before the failure adds up to the budget: the clock ran in R IV only
    parts = res.parts[res.parts.picked]
    end = parts.at_bot_s + parts.motion_cycle_s
    r4 = (np.minimum(end, first.from_s) - np.minimum(end - parts.r4_s, first.from_s)).clip(0)
    assert r4.sum() == pytest.approx(100.0, abs=1e-6)
    assert wear.told == len(parts)


def test_planned_stops_come_back_and_cost_the_parts_they_cover():
    f = {"maintenance": {"every_h": 1.0, "duration_min": 10.0}}
    res = simulate(load_scenario("baseline", {"run.hours": 3.0, "failures": f}))
    stops = res.stops()
    assert [s.cause for s in stops] == ["maintenance", "maintenance"]  # at 1 h and 2 h
    for s in stops:  # each starts once the robot is back at B, and lasts its 10 minutes
        assert 3600.0 <= s.from_s % 3600.0 + 3600.0 < 3600.0 + 60.0
        assert s.to_s - s.from_s == pytest.approx(600.0)
    r = res.summary
    assert r.robot_maintenance_fraction == pytest.approx(1200.0 / 10800.0)
    # the parts lost are those that reached B during the stops: about 1200 s of arrivals
    assert abs(r.parts_lost_downtime - 1200.0 / 22.586) <= 3
    assert r.parts_in_cell <= 2 and r.planned_time_s == pytest.approx(10800.0 - 1200.0)
    assert r.loss_downtime == 0.0  # planned stops are not downtime: outside the planned time
    busy_after = [x for x in res.state_spans() if x.equipment == "robot" and x.state == "busy"
                  and x.from_s > stops[-1].to_s]
    assert busy_after  # the robot works again after its last stop
