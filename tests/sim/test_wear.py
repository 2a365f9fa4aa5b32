"""The wear model (cell.sim.wear) against closed forms and scipy (SPEC §10; Nelson 1990)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy import stats

from cell.arm.motors import max_rates
from cell.plumbing.errors import ScenarioError
from cell.scenario.schema import default_scenario
from cell.sim.assembly import assemble
from cell.sim.simulation import simulate
from cell.sim.wear import (
    STRETCHES,
    CycleWear,
    WearModel,
    draw_thresholds,
    exposure,
    failure_probability,
    series_life_h,
)

EXPONENTS = (0.0, 0.5, 1.0, 2.0, 3.0)


@pytest.fixture(scope="module")
def cell():
    return assemble(default_scenario())


@pytest.mark.parametrize("p", EXPONENTS)
def test_constant_stress_integrates_to_time_over_life(p: float) -> None:
    """ε = T / η(S) for a constant stress, η(S) = η0 (S0/S)^p."""
    m = WearModel(exponent=p, rated_life_h=1000.0, reference_stress=0.75)
    eps = exposure([3600.0 * 40], [0.9], m)
    assert eps == pytest.approx(40 / (1000.0 * (0.75 / 0.9) ** p), rel=1e-12)
    assert m.life_h(0.9) == pytest.approx(1000.0 * (0.75 / 0.9) ** p, rel=1e-12)


@pytest.mark.parametrize("p", EXPONENTS)
def test_linear_ramp_integrates_to_its_closed_form(p: float) -> None:
    """S(t) = a + b t over [0, T]: ∫ (S/S0)^p / η0 dt = ((a+bT)^(p+1) − a^(p+1)) / (b (p+1) S0^p η0),
    reached by the piecewise-constant sum as the moves get shorter (midpoint rule, O(1/N²))."""
    a, b, hours, s0, eta0 = 0.2, 0.7 / 10.0, 10.0, 0.75, 500.0   # 0.2 → 0.9 over 10 h
    m = WearModel(exponent=p, rated_life_h=eta0, reference_stress=s0)
    closed = ((a + b * hours) ** (p + 1) - a ** (p + 1)) / (b * (p + 1) * s0 ** p * eta0)
    errors = []
    for n in (100, 1000):
        edges = np.linspace(0.0, hours, n + 1)
        mid = 0.5 * (edges[1:] + edges[:-1])
        errors.append(abs(float(exposure(np.diff(edges) * 3600.0, a + b * mid, m)) - closed))
    assert errors[1] <= 1e-6 * closed
    if p not in (0.0, 1.0):  # the rule is exact for a linear integrand
        assert errors[0] / errors[1] == pytest.approx(100.0, rel=0.05)


@pytest.mark.parametrize("p", (0.0, 1.0, 2.5))
def test_stretch_exposure_is_the_sum_over_its_moves(cell, p: float) -> None:
    """The breakpoint form of each stretch equals Σ over its moves of t_k/η(S_jk), at
    velocities from free to every move at its motor floor."""
    t, timing = cell.table, cell.timing
    m = WearModel(exponent=p)
    wear = CycleWear(t, timing, m)
    rows = t.segment_rows()
    rated = max_rates(t.path.load_oz, t.motors, 1.0)
    for name, w in zip(STRETCHES, wear.stretches, strict=True):
        r = rows[name]
        seg = getattr(timing, name)
        for scale in (1.0, 1.3, 2.0, 4.0):
            time_s = seg.floor_s * scale
            v = seg.velocity(time_s)
            tk = np.maximum(t.velocity_lengths[r] / v, t.peak_min_times[r])
            stress = np.abs(t.steps[r]) / tk[:, None] / rated[r]
            assert np.allclose(w.at_time(time_s), exposure(tk, stress, m), rtol=1e-10, atol=0)


def test_r4_exposure_against_its_time_per_exponent(cell) -> None:
    """R IV is base moves only, at one step rate up to the rounding of each chord's steps (23
    or 24): its exposure scales as (time)^(1−p), to that rounding (0.1 %).
    The fixed robot's shortest cycle (R IV at the peak, Table 7.1) against the nominal R IV:
    p = 0 wears less (less time moving), p = 1 the same (life in steps), p = 2 more."""
    r4 = STRETCHES.index("r4")
    nominal, peak = cell.k.r4_nom, cell.timing.r4_min_s
    for p in (0.0, 1.0, 2.0, 3.0):
        w = CycleWear(cell.table, cell.timing, WearModel(exponent=p)).stretches[r4]
        ratio = w.at_time(peak)[0] / w.at_time(nominal)[0]
        assert ratio == pytest.approx((peak / nominal) ** (1 - p), rel=2e-3)
        if p != 1.0:
            assert (ratio < 1) == (p < 1)


@settings(max_examples=60, deadline=None)
@given(scales=st.lists(st.floats(1.0, 3.0), min_size=6, max_size=6),
       nudge=st.floats(-1e-6, 1e-6))
def test_life_in_steps_a_cycle_wears_its_steps_whatever_its_times(cell, scales, nudge) -> None:
    """p = 1: a move's exposure is its steps over the rated steps, whatever its time, so every
    cycle wears each motor the same (to rounding); and a cycle's exposure looked up by its
    stretches' intervals (another cycle's in the same intervals) is, to the bit, the sum over
    its stretches that it would compute."""
    wear = CycleWear(cell.table, cell.timing, WearModel(exponent=1.0))
    floor = [getattr(cell.timing, name).floor_s for name in STRETCHES]
    times = [f * k for f, k in zip(floor, scales)]
    other = [t * (1.0 + nudge) for t in times]
    assume(all(w.interval(a) == w.interval(b)
               for w, a, b in zip(wear.stretches, times, other)))
    assert np.allclose(wear.of_times(times), wear.of_times(floor), rtol=1e-9, atol=0)
    looked_up = wear.of_times(other)
    summed = [sum(col) for col in zip(*(w.at_time(t) for w, t in zip(wear.stretches, other)))]
    assert looked_up == summed


def test_weibull_in_exposure_at_constant_stress_is_scipy_weibull_min() -> None:
    """At a constant stress, ε = t/η(S): failing at ε = E^(1/β) is Weibull(β, η(S)) in time."""
    m = WearModel(exponent=2.0, rated_life_h=800.0, reference_stress=0.75, shape=1.7)
    stress = 1.0
    eta = m.life_h(stress)
    lives = draw_thresholds(np.random.default_rng(7), 4000, m) * eta
    assert stats.kstest(lives, stats.weibull_min(m.shape, scale=eta).cdf).pvalue > 0.01
    hours = np.array([10.0, 200.0, 450.0, 2000.0])
    eps = exposure(np.broadcast_to(hours * 3600.0, (1, 4)), np.full((1, 4), stress), m)
    assert np.allclose(failure_probability(eps, m),
                       stats.weibull_min.cdf(hours, m.shape, scale=eta), rtol=1e-12)


def test_motors_in_series_are_weibull_of_the_combined_life() -> None:
    lives, beta = [1000.0, 2500.0, 4000.0, math.inf], 2.0
    eta = series_life_h(lives, beta)
    t = np.array([100.0, 700.0, 1500.0])
    product = np.prod([stats.weibull_min.sf(t, beta, scale=x) for x in lives[:3]], axis=0)
    assert np.allclose(stats.weibull_min.sf(t, beta, scale=eta), product, rtol=1e-12)


def test_wear_off_or_never_failing_leaves_the_run_unchanged() -> None:
    base = default_scenario().with_overrides({"run.parts": 300})
    off = simulate(base, keep_parts=False, keep_belts=False)
    assert off.wear is None
    never = simulate(base.with_overrides({"wear.enabled": True, "wear.rated_life_h": 1e7}),
                     keep_parts=False, keep_belts=False)
    assert never.summary == off.summary
    assert never.wear is not None and never.wear["wear_failures"] == 0


@pytest.mark.parametrize("policy", ("adaptive", "non-adaptive"))
def test_a_worn_motor_stops_the_robot_for_its_repair(policy: str) -> None:
    """Short lives: the robot stops; no part is picked while it is down, the parts that come
    then ride off, and every part is still accounted for."""
    s = default_scenario().with_overrides({
        "run.parts": 1500, "controller.policy": policy, "wear.enabled": True,
        "wear.rated_life_h": 0.5, "wear.repair_h": 0.1})
    worn = simulate(s)
    clean = simulate(s.with_overrides({"wear.enabled": False}))
    assert worn.wear is not None and worn.wear["wear_failures"] == len(worn.wear.stops) > 2
    picks = np.array([r.pick_s for r in worn.records if r.picked])
    for start, end, joint in worn.wear.stops:
        assert end - start == pytest.approx(360.0) and 0 <= joint < 5
        assert not np.any((picks > start + 1e-9) & (picks < end - 1e-9))
    w, c = worn.summary, clean.summary
    assert w.parts_missed > c.parts_missed
    assert w.parts_delivered + w.parts_missed + w.parts_in_cell == w.parts_arrived


@pytest.mark.parametrize("key, value", (("wear.exponent", -1.0), ("wear.rated_life_h", 0.0),
                                        ("wear.shape", 0.0), ("wear.repair_h", -2.0)))
def test_bad_wear_values_name_the_key(key: str, value: float) -> None:
    with pytest.raises(ScenarioError, match=key.replace(".", r"\.")):
        default_scenario().with_overrides({key: value})


def test_with_failures_the_robot_clock_counts_wear_and_logs_it() -> None:
    """wear: with failures.robot: the failures' robot clock counts the motors' exposure
    instead of its drawn time to failure; failures.csv's stops say ``wear``, each repaired for
    the drawn time to repair, and the run's wear measures count them."""
    s = default_scenario().with_overrides({
        "run.parts": 800, "wear.enabled": True, "wear.rated_life_h": 0.5,
        "failures": {"robot": {"time_to_failure": {"distribution": "expon",
                                                   "params": {"scale": 1e9}},
                               "time_to_repair": {"distribution": "uniform",
                                                  "params": {"loc": 100.0, "scale": 100.0}}}}})
    run = simulate(s, keep_parts=False, keep_belts=False)
    stops = [x for x in run.stops() if x.equipment == "robot"]
    assert len(stops) > 2 and {x.cause for x in stops} == {"wear"}
    assert all(100.0 - 1e-9 <= x.to_s - x.from_s <= 200.0 + 1e-9 for x in stops[:-1])
    assert run.wear is not None and run.wear["wear_failures"] == len(stops)
    assert run.wear["wear_availability"] == pytest.approx(
        run.wear["wear_mtbf_h"] / (run.wear["wear_mtbf_h"] + 150.0 / 3600.0))


def test_wear_with_failures_but_no_robot_entry_is_refused() -> None:
    with pytest.raises(ScenarioError, match=r"wear\.enabled.*failures\.robot"):
        default_scenario().with_overrides({
            "wear.enabled": True,
            "failures": {"sensor": {"time_to_failure": {"distribution": "expon",
                                                        "params": {"scale": 100.0}},
                                    "time_to_repair": {"distribution": "expon",
                                                       "params": {"scale": 10.0}}}}})


# --------------------------------------------------------------------------- in the long run
#: Short lives and repairs, so a few simulated days hold hundreds of stops (p = 0: the motors'
#: lives differ most, so five fresh motors' mean life is twice the renewal figure).
RENEWAL = {"controller.policy": "non-adaptive", "wear.enabled": True, "wear.exponent": 0.0,
           "wear.rated_life_h": 1.0, "wear.repair_h": 0.02, "run.hours": 100.0}
WARM_UP_S = 10 * 3600.0  # a few lives of the longest-lived motor: the stops are stationary after


@pytest.fixture(scope="module")
def renewal_runs():
    s = default_scenario().with_overrides(RENEWAL)
    return [simulate(s, seed=seed, keep_parts=False, keep_belts=False) for seed in range(10)]


def test_wear_mtbf_is_the_long_run_mean_time_between_wear_stops(renewal_runs) -> None:
    """Only the worn motor is replaced, so each motor's place is a renewal process of mean
    η_j Γ(1 + 1/β) and the robot stops at their summed rates: wear_mtbf_h is the up time
    between stops the run shows once past its start (fresh motors), within a 99 % interval
    over the replications (a ratio estimator: up time over stops)."""
    up, n, mtbf = [], [], []
    for run in renewal_runs:
        end = run.summary.sim_end_s
        late = [(a, min(b, end)) for a, b, _ in run.wear.stops if WARM_UP_S <= a < end]
        up.append((end - WARM_UP_S - sum(b - a for a, b in late)) / 3600.0)
        n.append(len(late))
        mtbf.append(run.wear["wear_mtbf_h"])
    u, k = np.array(up), np.array(n, dtype=float)
    ratio = u.sum() / k.sum()
    se = np.sqrt(np.sum((u - ratio * k) ** 2) / (k.size * (k.size - 1))) / k.mean()
    half = stats.t.ppf(0.995, k.size - 1) * se
    assert k.min() > 150 and half < 0.06 * ratio  # enough stops for the interval to mean much
    assert abs(np.mean(mtbf) - ratio) <= half


def test_wear_alone_stops_are_in_the_failures_the_states_and_the_summary(renewal_runs) -> None:
    """wear: without failures: each stop is a failures.csv row (robot, wear), the robot is
    ``down`` in states.csv exactly then, and the summary's downtime loss, down fraction and
    observed MTBF count the stops (nothing else stops this cell)."""
    run = renewal_runs[0]
    r, end = run.summary, run.summary.sim_end_s
    stops = run.stops()
    assert run.wear is not None and len(stops) == run.wear["wear_failures"] > 50
    assert {(x.equipment, x.cause, x.part) for x in stops} == {("robot", "wear", "")}
    assert np.allclose([(x.from_s, x.to_s) for x in stops],
                       [(a, min(b, end)) for a, b, _ in run.wear.stops if a < end])
    down_s = sum(x.to_s - x.from_s for x in stops)
    assert down_s / 3600.0 == pytest.approx(run.wear["wear_down_h"])
    robot = [s for s in run.state_spans() if s.equipment == "robot"]
    assert robot[0].from_s == 0 and robot[-1].to_s == end
    assert all(a.to_s == b.from_s for a, b in zip(robot, robot[1:]))
    assert np.allclose([(s.from_s, s.to_s) for s in robot if s.state == "down"],
                       [(x.from_s, x.to_s) for x in stops])
    assert r.robot_down_fraction == pytest.approx(down_s / end)
    assert r.loss_downtime == pytest.approx(down_s / end) and r.loss_downtime > 0
    assert r.robot_failures == len(stops)
    assert r.mtbf_observed_s == pytest.approx((end - down_s) / len(stops))
    assert r.oee == pytest.approx(r.availability * r.performance * r.quality)


@settings(max_examples=20, deadline=None)
@given(p=st.sampled_from(EXPONENTS),
       scales=st.lists(st.lists(st.floats(1.0, 3.0), min_size=6, max_size=6), min_size=1,
                       max_size=30))
def test_many_cycles_wear_as_each_alone_to_the_bit(cell, p, scales) -> None:
    """The exposure of many cycles at once is each cycle's own (``of_many`` and ``of_times``),
    the same floats, whatever the cycles' times and order."""
    floor = [getattr(cell.timing, name).floor_s for name in STRETCHES]
    times = [tuple(f * k for f, k in zip(floor, row)) for row in scales]
    many = CycleWear(cell.table, cell.timing, WearModel(exponent=p)).of_many(times)
    one = CycleWear(cell.table, cell.timing, WearModel(exponent=p))
    assert many.tolist() == [one.of_times(t) for t in times]


@pytest.mark.parametrize("p", [1.0, 2.0])
def test_a_wear_clock_that_keeps_cycles_fails_when_one_that_takes_each_does(cell, p) -> None:
    """A failure clock counting wear takes the cycles' use lazily while no motor is near its
    end (the exposure's bound a second, :meth:`CycleWear.peak_rates`); its failures come at the
    very instants, and its motors' totals are the very floats, of a clock told no bound (every
    cycle's use taken as it starts)."""
    import simpy

    from cell.sim.failure_clock import MOVING_NOT, FailureClock
    from cell.sim.wear_clock import WearExposure

    class EachCycle(WearExposure):
        def peak_rates(self):  # noqa: ANN202
            return None

    floor = [getattr(cell.timing, name).floor_s for name in STRETCHES]
    rng = np.random.default_rng(5)
    legs = [tuple(f * k for f, k in zip(floor, rng.uniform(1.0, 2.5, 6))) for _ in range(4000)]
    idle = rng.exponential(3.0, len(legs)).tolist()

    def run(kind: type) -> tuple[list[tuple[int, float]], list[float], int]:
        env = simpy.Environment()
        exposure = kind(CycleWear(cell.table, cell.timing, WearModel(exponent=p,
                                                                    rated_life_h=2.0)),
                        np.random.default_rng(11))
        failed: list[tuple[int, float]] = []

        def fail(component, cause):  # noqa: ANN001, ANN202
            failed.append((component, env.now))
            yield env.timeout(60.0)

        clock = FailureClock(env, exposure, fail, MOVING_NOT)
        kept = [0]

        def robot():  # noqa: ANN202
            for cycle, wait in zip(legs, idle):
                end = env.now + sum(cycle)
                if clock.cycle(cycle, end):
                    kept[0] += bool(clock.pending)
                    yield env.timeout(end - env.now)
                else:  # near a motor's end: leg by leg
                    for i, leg in enumerate(cycle):
                        clock.follow(i)
                        yield env.timeout(leg)
                    clock.follow(MOVING_NOT)
                while clock.failing:
                    yield env.timeout(1.0)
                yield env.timeout(wait)

        env.process(robot())
        env.run()
        clock.settle()
        return failed, exposure.total, kept[0]

    lazy, each = run(WearExposure), run(EachCycle)
    assert len(each[0]) >= 3  # the motors wear out several times
    assert lazy[:2] == each[:2]
    assert lazy[2] > len(legs) // 2 and each[2] == 0  # most cycles were kept
