"""The policies' decisions (cell.sim.policies) against thesis §5.3, §6.3 and Table 7.1."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.cli.main import main
from cell.plumbing.errors import ScenarioError
from cell.scenario import catalog, registry
from cell.sim.policies import Plan, Policy
from cell.sim.policies.adaptive import adaptive_plan
from cell.sim.policies.fixed import fixed_plan
from cell.sim.records import INPUT_FLOOR, OUTPUT_CEILING, OUTPUT_FLOOR, R2_PEAK, R4_PEAK
from cell.sim.simulation import simulate

#: Table 7.1: ideal cycle -> Vavg R IV (in/s).
VAVG_R4 = {22.5872: 3.5594, 22.0: 3.7818, 21.5: 3.9943, 21.0: 4.2321, 20.5: 4.5000,
           20.0907: 4.7459}


@pytest.mark.parametrize("ideal", sorted(VAVG_R4))
def test_fixed_cycle_shortens_r4_only_as_in_table_7_1(k, ideal):
    plan = fixed_plan(k, ideal)
    assert plan.cycle == pytest.approx(ideal, abs=5e-4)
    assert plan.r4 >= k.timing.r4_min_s
    assert k.timing.r4.length_in / plan.r4 == pytest.approx(VAVG_R4[ideal], abs=1.5e-3)
    assert (plan.r1_pre, plan.r2, plan.r3_pre) == (k.r1_pre_nom, k.r2_nom, k.r3_pre_nom)


def test_nominal_regimes_add_up_to_the_ideal_cycle(k):
    assert k.r1_nom + k.r2_nom + k.r3_pre_nom + k.r3_post_nom + k.r4_nom == \
        pytest.approx(22.5872, abs=1e-9)
    # docs/model.md derives R II = 5.9350 s from an R I of exactly 8/3 s; the motor floor
    # after LO lengthens R I a little and R II gives that back.
    assert k.r2_nom == pytest.approx(5.9350, abs=0.1)
    assert k.r2_nom < 5.9350


def test_a_cycle_shorter_than_the_base_allows_is_an_error(k):
    with pytest.raises(ScenarioError, match="controller.ideal_cycle_s"):
        fixed_plan(k, 20.0)


def test_on_time_part_keeps_everything_nominal(k):
    # next part exactly one nominal cycle away at the nominal belt speed
    lag = k.timing.r1_pre.time(3.0)
    b = (k.cycle_nom - lag) * 3.0
    gap = 45.0 - 2.0 * (k.r1_nom + k.r2_nom) - 2.0 * k.r3_pre_nom
    plan = adaptive_plan(k, 3.0, (lag, b), gap)
    assert plan.cycle == pytest.approx(k.cycle_nom)
    assert plan.input_after_lo == pytest.approx(3.0)
    assert plan.output_to_g == pytest.approx(2.0)
    assert plan.limits == 0


def test_late_part_speeds_the_input_belt_after_the_lag(k):
    lag = k.timing.r1_pre.time(3.0)
    b = (k.cycle_nom + 1.5 - lag) * 3.0          # 1.5 s late at the current speed
    plan = adaptive_plan(k, 3.0, (lag, b), None)
    assert plan.cycle == pytest.approx(k.cycle_nom)
    assert plan.input_after_lo > 3.0
    assert lag + b / plan.input_after_lo == pytest.approx(plan.cycle)   # at B as robot returns
    assert plan.input_next == pytest.approx((plan.input_after_lo + 3.0) / 2)  # step 6.3


def test_early_part_is_made_up_in_r4_first(k):
    lag = k.timing.r1_pre.time(3.0)
    b = (k.cycle_nom - 1.0 - lag) * 3.0          # 1 s early
    plan = adaptive_plan(k, 3.0, (lag, b), None)
    assert plan.r4 == pytest.approx(k.r4_nom - 1.0)
    assert plan.input_after_lo == 3.0
    assert plan.cycle == pytest.approx(lag + b / 3.0)


def test_very_early_part_uses_the_base_maximum_then_slows_the_belt(k):
    lag = k.timing.r1_pre.time(3.0)
    b = (k.cycle_nom - 4.0 - lag) * 3.0          # 4 s early: more than R IV can give
    plan = adaptive_plan(k, 3.0, (lag, b), None)
    assert plan.r4 == pytest.approx(k.timing.r4_min_s)
    assert plan.input_after_lo < 3.0
    assert lag + b / plan.input_after_lo == pytest.approx(plan.cycle)
    assert plan.input_next == plan.input_after_lo     # 6.3: below nominal, left alone
    assert plan.limits == R4_PEAK


def test_no_slower_than_the_floor_and_a_too_early_part_is_let_go(k):
    """Departure: step 3.2 stops at belts.input_min_in_s; the part comes early (and the
    controller, which aimed it at B for the robot's return, says so)."""
    lag = k.timing.r1_pre.time(3.0)
    b = 4.0                                      # the next part is right behind
    plan = adaptive_plan(k, 3.0, (lag, b), None)
    assert plan.input_after_lo == k.input_min
    assert lag + b / plan.input_after_lo < plan.cycle           # it will reach B early
    assert plan.limits & INPUT_FLOOR and plan.limits & R4_PEAK


def test_a_belt_left_slower_than_r2_can_absorb_is_raised(k):
    """Departure in step 6.3: below ``input_absorb`` the next R I would outgrow R II's slack
    (step 2.2) and lengthen the cycle; the belt is raised to that speed.  At it, R II takes
    exactly its fastest time."""
    lag = k.timing.r1_pre.time(3.0)
    b = (k.input_min + 0.05) * (k.shortest_cycle_s - lag)   # slowed to just above the floor
    plan = adaptive_plan(k, 3.0, (lag, b), None)
    assert k.input_min < plan.input_after_lo < k.input_absorb
    assert plan.input_next == k.input_absorb
    after = adaptive_plan(k, plan.input_next, None, None)
    assert after.r2 == pytest.approx(k.timing.r2_min_s, rel=1e-6)
    assert after.cycle == pytest.approx(k.cycle_nom, rel=1e-9)


def test_fast_input_belt_gives_its_time_to_r2(k):
    v = 4.0
    plan = adaptive_plan(k, v, None, None)
    r1 = plan.r1_pre + plan.r1_post
    assert r1 < k.r1_nom
    assert plan.r2 == pytest.approx(k.r2_nom + (k.r1_nom - r1))   # step 2.1
    assert plan.cycle == pytest.approx(k.cycle_nom)


def test_output_speed_is_the_average_of_the_spacing_limits(k):
    gap = 20.0
    plan = adaptive_plan(k, 3.0, None, gap)
    ttsot = plan.to_g
    lo = (44.75 - gap - 2.0 * plan.r3_pre) / ttsot          # step 5.0
    hi = (45.25 - gap - 2.0 * plan.r3_pre) / ttsot
    assert plan.output_to_g == pytest.approx((lo + hi) / 2)
    assert gap + plan.output_to_g * ttsot + 2.0 * plan.r3_pre == pytest.approx(45.0)


@settings(max_examples=150, deadline=None)
@given(v=st.floats(0.3, 4.3), a=st.floats(0.0, 40.0), b=st.floats(0.01, 200.0),
       gap=st.one_of(st.none(), st.floats(0.0, 60.0)))
def test_plans_never_ask_more_than_the_motors_and_belts_can_do(k, v, a, b, gap):
    v = min(max(v, k.input_min), k.timing.input_track_max_in_s)   # a belt is never outside them
    plan = adaptive_plan(k, v, (a, b), gap)
    t = k.timing
    assert plan.r1_pre >= t.r1_pre.floor_s - 1e-12
    assert plan.r1_post >= t.r1_post.floor_s - 1e-12
    assert plan.r2 >= t.r2_min_s - 1e-12
    assert plan.r4 >= t.r4_min_s - 1e-12
    assert k.input_min <= plan.input_after_lo <= k.input_max
    assert min(v, k.input_absorb) <= plan.input_next <= t.input_track_max_in_s
    assert k.output_min <= plan.output_to_g <= k.output_max
    assert math.isfinite(plan.cycle) and 0 < plan.cycle <= k.cycle_nom + 1e-9 or \
        plan.limits & R2_PEAK
    if not plan.limits & (OUTPUT_FLOOR | OUTPUT_CEILING) and gap is not None:
        spacing = gap + plan.output_to_g * plan.to_g + k.u_nom * plan.r3_pre
        assert spacing == pytest.approx(45.0, abs=1e-9)


# --------------------------------------------------------------------------- a plug-in policy
class AlwaysNominal(Policy):
    """A policy defined only here: every part gets the nominal cycle, belts untouched."""

    name = "always-nominal"

    def plan(self, view):
        k = self.k
        return Plan(r1_pre=k.r1_pre_nom, r1_post=k.r1_post_nom, r2=k.r2_nom,
                    r3_pre=k.r3_pre_nom, r3_post=k.r3_post_nom, r4=k.r4_nom,
                    input_speed=k.v_nom, input_after_lo=k.v_nom, input_next=k.v_nom,
                    output_to_g=k.u_nom, to_g=k.r1_nom + k.r2_nom, cycle=k.cycle_nom,
                    steers_belts=False)


@pytest.fixture
def plug_in():
    registry.register(AlwaysNominal)
    yield AlwaysNominal.name
    registry.unregister(AlwaysNominal.name)


def test_a_policy_from_outside_the_package_runs_like_the_fixed_cycle_it_is(plug_in, thesis_cell):
    """The plug-in is physically the non-adaptive robot at the nominal cycle (§6.3): the
    same parts are lost and delivered at the same instants."""
    s = thesis_cell.with_overrides({"run.parts": 300, "controller.policy": plug_in})
    ours = simulate(s, seed=5)
    fixed = simulate(s.with_overrides({"controller.policy": "non-adaptive"}), seed=5)
    assert ours.summary.policy == plug_in
    assert ours.summary.parts_missed == fixed.summary.parts_missed > 0
    np.testing.assert_allclose(ours.parts["touchdown_s"], fixed.parts["touchdown_s"], rtol=1e-12)
    assert ours.belt_changes == [c for c in fixed.belt_changes]   # never steered


@pytest.mark.usefixtures("unlaid")
def test_a_plug_in_policy_runs_through_a_sweep(plug_in, tmp_path, capsys):
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(f"base: {catalog.path('baseline')}\nset: {{run.parts: 60}}\n"
                     f"policies: [{plug_in}, non-adaptive]\nreplications: 3\nseed: 7\n")
    report = tmp_path / "report"
    assert main(["sweep", str(sweep), "--out", str(tmp_path / "out"), "--workers", "1",
                 "--report", str(report)]) == 0
    rows = pd.read_csv(tmp_path / "out" / "replications.csv")
    assert sorted(set(rows["policy"])) == sorted([plug_in, "non-adaptive"])
    by = rows.groupby("policy")["parts_missed"].apply(list)
    assert by[plug_in] == by["non-adaptive"]
    # the report treats the plug-in as any policy: summarised, and paired with the other
    summary = pd.read_csv(report / "summary.csv")
    assert set(summary["policy"]) == {plug_in, "non-adaptive"}
    missed = summary[summary["measure"] == "parts_missed"].set_index("policy")["mean"]
    assert missed[plug_in] == missed["non-adaptive"] == pytest.approx(np.mean(by[plug_in]), rel=1e-9)
    differences = pd.read_csv(report / "differences.csv")
    paired = differences[differences["measure"] == "parts_missed"]
    assert len(paired) == 1 and paired["mean"].iloc[0] == 0
    assert plug_in in (report / "report.md").read_text()


def test_an_unknown_policy_lists_the_known_ones(thesis_cell):
    with pytest.raises(ScenarioError, match="must be one of non-adaptive, adaptive"):
        thesis_cell.with_overrides({"controller.policy": "random"})
