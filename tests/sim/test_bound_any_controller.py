"""The bound holds for every controller the plan check lets run (issue 35, item 1): the check
(cell/sim/policies/check.py, the controller's inline copy) and the bound (cell/sim/bound.py)
read one statement of what a cycle may take (RobotTiming.shortest_parts, docs/model.md).

A plug-in that tracks honestly down to LO, times G → TD at the output belt's real speed and
runs R II, R IV and TD → K at the motors' floors used to pass the check and deliver more than
``parts_bound`` (10 parts against 9); the check now refuses TD → K below the output belt's
pace, as the thesis's R III (4.0 s at 2 in/s) tracks the belt to K.  Over random plug-ins
(each regime at the motors' floor, at its belt's pace or slower; belts steered anyhow) and
random traces, a run the check lets finish never delivers more than the bound."""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np
import pytest
from hypothesis import event, example, given, settings
from hypothesis import strategies as st

from cell.scenario import registry
from cell.scenario.schema import default_scenario
from cell.sim.assembly import assemble
from cell.sim.policies.base import Plan, Policy
from cell.sim.policies.check import PolicyError, problem
from tests.sim.test_sensor import run_trace

NAME = "bound-test-plug-in"
PARTS = 10
#: Input belts (in): as short as a part's reach of B leaves the controller almost no slack,
#: and the thesis's cell's.
LENGTHS = (8.0, 30.0, 135.52)
#: Nominal input speeds (in/s): the thesis's, and a hair under the tracking limit (the first
#: part is then picked as fast as the robot can follow).
NOMINALS = (3.0, 4.3692)


class Sprinter(Policy):
    """The plug-in of issue 35: R I at the pace of the belt it is on, R II and R IV at their
    peak, G → TD at the output belt's nominal pace and TD → K at ``r3_post`` (the motors' floor
    unless the test says), the next part aimed at B for the robot's return and picked at the
    fastest input belt the robot can follow."""

    name = NAME
    r3_post: ClassVar[float | None] = None

    def plan(self, view: Any) -> Plan:
        k = self.k
        t = k.timing
        v = view.input_speed()
        r1a, r1b = t.r1_time(v)
        r3b = t.r3_post.floor_s if self.r3_post is None else self.r3_post
        r2, r3a, r4 = t.r2_min_s, t.r3_pre.time(k.u_nom), t.r4_min_s
        cycle = r1a + r1b + r2 + r3a + r3b + r4
        fast = min(t.input_track_max_in_s, k.input_max)
        w = _aim(k, view.next_part(r1a, v), cycle, v)
        return Plan(r1_pre=r1a, r1_post=r1b, r2=r2, r3_pre=r3a, r3_post=r3b, r4=r4,
                    input_speed=v, input_after_lo=w, input_next=fast, output_to_g=k.u_nom,
                    to_g=r1a + r1b + r2, cycle=cycle, steers_belts=True,
                    output_floor_at=math.inf)


def _aim(k: Any, nxt: tuple[float, float] | None, cycle: float, v: float) -> float:
    """The input belt after LO that brings the next part to B as the robot gets back."""
    if nxt is None:
        return v
    a, b = nxt
    w = b / (cycle - a) if cycle > a else k.input_max
    return min(max(w, k.input_min), k.input_max)


class Drawn(Policy):
    """A plug-in whose every choice the test draws: each regime at the motors' floor, at its
    belt's pace (the input belt's at the pick, the output belt's nominal or the fastest the
    robot can follow) plus a drawn extra; the input belt after LO aimed or drawn, after the
    cycle drawn; ``input_speed`` the belt's or claimed the fastest."""

    name = NAME + "-drawn"
    style: ClassVar[dict[str, Any]] = {}

    def plan(self, view: Any) -> Plan:
        k, st_ = self.k, self.style
        t = k.timing
        rng: np.random.Generator = st_["rng"]
        fast_in, fast_out = min(t.input_track_max_in_s, k.input_max), \
            min(t.output_track_max_in_s, k.output_max)
        v = view.input_speed() if st_["honest"] else fast_in
        pace = {"floor": (t.r1_pre.floor_s, t.r1_post.floor_s, t.r2_min_s, t.r3_pre.floor_s,
                          t.r3_post.floor_s, t.r4_min_s),
                "belt": (*t.r1_time(v), t.r2_min_s, *t.r3_time(k.u_nom), t.r4_min_s),
                "fastest": (*t.r1_time(fast_in), t.r2_min_s, *t.r3_time(fast_out), t.r4_min_s)}
        times = [pace[how][i] + extra * rng.random()
                 for i, (how, extra) in enumerate(zip(st_["how"], st_["extra"]))]
        r1a, r1b, r2, r3a, r3b, r4 = times
        cycle = r1a + r1b + r2 + r3a + r3b + r4
        w = _aim(k, view.next_part(r1a, v), cycle, v) if st_["aim"] else \
            k.input_min + (k.input_max - k.input_min) * rng.random()
        w_next = fast_in if st_["next_fast"] else k.input_min + (fast_in - k.input_min) * rng.random()
        return Plan(r1_pre=r1a, r1_post=r1b, r2=r2, r3_pre=r3a, r3_post=r3b, r4=r4,
                    input_speed=v, input_after_lo=w, input_next=w_next, output_to_g=k.u_nom,
                    to_g=r1a + r1b + r2, cycle=cycle, steers_belts=True,
                    output_floor_at=math.inf)


@pytest.fixture(scope="module")
def cells():
    """The two plug-ins registered, and the cell assembled for each (plug-in, input belt
    length, nominal input speed), ``PARTS`` parts."""
    registry.register(Sprinter)
    registry.register(Drawn)
    base = default_scenario().with_overrides({"run.parts": PARTS})
    yield {(p, length, nominal): assemble(base.with_overrides({
        "controller.policy": p, "belts.input_length_in": length,
        "belts.input_nominal_in_s": nominal}))
        for p in (Sprinter.name, Drawn.name) for length in LENGTHS for nominal in NOMINALS}
    registry.unregister(Sprinter.name)
    registry.unregister(Drawn.name)


def _delivered_and_bound(cell: Any, gaps: list[float]) -> tuple[int, int] | None:
    """(parts delivered, the bound) of a run on the trace ``gaps``; None if the check refused
    a plan."""
    try:
        s = run_trace(cell, gaps).summary
    except PolicyError:
        return None
    return s.parts_delivered, s.parts_bound


def test_the_plug_in_of_the_issue_is_refused_and_at_the_belts_pace_stays_within_the_bound(
        cells: dict) -> None:
    """10 parts 16 s apart on an 8 in input belt: TD → K at the motors' floor (0.8191 s) is
    below the output belt's pace and refused (it delivered 10 against a bound of 9); at the
    pace (2.0052 s at 2 in/s) the same plug-in delivers no more than the bound."""
    cell = cells[(Sprinter.name, 8.0, 4.3692)]
    Sprinter.r3_post = None
    assert _delivered_and_bound(cell, [16.0] * (PARTS + 1)) is None
    t, k = cell.k.timing, cell.k
    Sprinter.r3_post = t.r3_post.time(k.u_nom)
    try:
        delivered, bound = _delivered_and_bound(cell, [16.0] * (PARTS + 1))
    finally:
        Sprinter.r3_post = None
    assert delivered <= bound == 9


def test_the_check_names_td_to_k_below_the_output_belts_pace(k) -> None:
    t = k.timing
    plan = Plan(r1_pre=k.r1_pre_nom, r1_post=k.r1_post_nom, r2=k.r2_nom, r3_pre=k.r3_pre_nom,
                r3_post=t.r3_post.floor_s, r4=k.r4_nom, input_speed=k.v_nom,
                input_after_lo=k.v_nom, input_next=k.v_nom, output_to_g=k.u_nom,
                to_g=k.r1_nom + k.r2_nom,
                cycle=k.r1_nom + k.r2_nom + k.r3_pre_nom + t.r3_post.floor_s + k.r4_nom,
                steers_belts=False)
    why = problem(plan, k)
    assert why is not None and why.startswith("r3_post =") and f"{k.r3_post_nom:.6g}" in why


_HOW = st.sampled_from(["belt"] * 6 + ["floor", "fastest"])
_EXTRA = st.sampled_from([0.0, 0.0, 0.05, 1.0])


@settings(max_examples=60, deadline=None)
@example(length=8.0, nominal=4.3692, gap=16.0, jitter=[0.0] * (PARTS + 1), seed=0,
         how=["belt", "belt", "floor", "belt", "floor", "floor"], extra=[0.0] * 6, honest=True,
         aim=True, next_fast=True)
@example(length=135.52, nominal=4.3692, gap=16.2, jitter=[0.0] * (PARTS + 1), seed=0,
         how=["floor"] * 6, extra=[0.0] * 6, honest=True, aim=True, next_fast=True)
@given(length=st.sampled_from(LENGTHS), nominal=st.sampled_from(NOMINALS),
       gap=st.floats(14.0, 24.0), jitter=st.lists(st.sampled_from([0.0, -1.0, 1.0]) |
                                                  st.floats(-4.0, 4.0),
                                                  min_size=PARTS + 1, max_size=PARTS + 1),
       seed=st.integers(0, 2**32 - 1), how=st.lists(_HOW, min_size=6, max_size=6),
       extra=st.lists(_EXTRA, min_size=6, max_size=6), honest=st.booleans(),
       aim=st.booleans(), next_fast=st.booleans())
def test_no_plug_in_the_check_lets_run_delivers_more_than_the_bound(
        cells: dict, length: float, nominal: float, gap: float, jitter: list[float], seed: int,
        how: list[str], extra: list[float], honest: bool, aim: bool, next_fast: bool) -> None:
    _holds(cells[(Drawn.name, length, nominal)], [max(gap + j, 0.0) for j in jitter],
           {"rng": np.random.default_rng(seed), "how": how, "extra": extra, "honest": honest,
            "aim": aim, "next_fast": next_fast})


def _holds(cell, gaps: list[float], style: dict) -> None:
    """The drawn plug-in (``style``) on ``gaps``: refused, or no more parts than the bound."""
    Drawn.style = style
    got = _delivered_and_bound(cell, gaps)
    event("refused" if got is None else "ran")
    if got is not None:
        delivered, bound = got
        event("bound reached" if delivered == bound else "below the bound")
        assert delivered <= bound


#: Gaps between parts in bursts: at once, closer than a part's size at the ceiling, a few
#: parts' sizes at the floor, about a cycle.
_BURST_GAP = st.sampled_from([0.0, 0.0, 0.1]) | st.floats(0.0, 3.0) | st.floats(14.0, 24.0)


@settings(max_examples=40, deadline=None)
@example(length=135.52, nominal=4.3692, gaps=[5.0] + [0.0] * PARTS, seed=0,
         how=["floor"] * 6, extra=[0.0] * 6, honest=True, aim=True, next_fast=True)
@example(length=8.0, nominal=3.0, gaps=[5.0, 0.0, 0.0, 2.9, 0.0, 1.4, 0.0, 0.0, 2.7, 0.0, 0.0],
         seed=0, how=["belt"] * 6, extra=[0.0] * 6, honest=True, aim=True, next_fast=True)
@given(length=st.sampled_from(LENGTHS), nominal=st.sampled_from(NOMINALS),
       gaps=st.lists(_BURST_GAP, min_size=PARTS + 1, max_size=PARTS + 1),
       seed=st.integers(0, 2**32 - 1), how=st.lists(_HOW, min_size=6, max_size=6),
       extra=st.lists(_EXTRA, min_size=6, max_size=6), honest=st.booleans(),
       aim=st.booleans(), next_fast=st.booleans())
def test_on_bursts_no_plug_in_delivers_more_than_the_one_belt_bound(
        cells: dict, length: float, nominal: float, gaps: list[float], seed: int,
        how: list[str], extra: list[float], honest: bool, aim: bool, next_fast: bool) -> None:
    """Parts in bursts, where the bound counts that they share one belt (cell/sim/bound.py):
    still no drawn plug-in the check lets run delivers more."""
    _holds(cells[(Drawn.name, length, nominal)], gaps,
           {"rng": np.random.default_rng(seed), "how": how, "extra": extra, "honest": honest,
            "aim": aim, "next_fast": next_fast})
