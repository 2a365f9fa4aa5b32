"""Belts as speed schedules (cell.sim.conveyors): travel is the integral of speed."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.sim.conveyors import Belt


def test_travel_integrates_piecewise_speeds():
    b = Belt(3.0)
    b.plan(10.0, 6.0, 20.0, 1.5)
    assert b.travel(10.0) == pytest.approx(30.0)
    assert b.travel(15.0) == pytest.approx(60.0)
    assert b.travel(30.0) == pytest.approx(30.0 + 60.0 + 15.0)
    assert b.speed(12.0) == 6.0 and b.speed(25.0) == 1.5


def test_new_plan_supersedes_later_changes():
    b = Belt(3.0)
    b.plan(10.0, 6.0, 20.0, 1.5)
    b.plan(15.0, 2.0)                   # replans from 15 s: the change at 20 s is gone
    assert b.speed(25.0) == 2.0
    assert b.travel(25.0) == pytest.approx(30.0 + 30.0 + 20.0)


def test_a_plan_cannot_start_before_what_the_belt_holds():
    b = Belt(3.0)
    b.plan(10.0, 6.0, 20.0, 1.5)
    b.plan(30.0, 2.0)                   # settles the changes before 20 s
    with pytest.raises(ValueError, match="before its earliest held change"):
        b.plan(5.0, 4.0)
    assert b.speed(25.0) == 1.5 and b.speed(35.0) == 2.0  # the schedule is as it was
    with pytest.raises(ValueError, match="before its earliest held change"):
        Belt(3.0).plan(-1.0, 4.0)


def test_travel_a_rounding_before_the_earliest_held_change():
    """The controller may replan up to EPS_S before the robot's cycle ends, where the belt
    changes speed; a replan then keeps only that change, and the belt's travel just before
    it is still the travel there (it read the last change's line, far off)."""
    b = Belt(3.0)
    b.plan(10.0, 6.0, 20.0, 1.5)
    b.plan(21.0, 4.0, 30.0, 2.0)        # settles the changes before 20 s
    assert b.travel(20.0 - 3e-13) == pytest.approx(90.0, abs=1e-9)  # 3 x 10 + 6 x 10
    assert b.speed(20.0 - 3e-13) == 1.5


def test_speed_must_be_positive():
    with pytest.raises(ValueError):
        Belt(3.0).plan(1.0, 0.0)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0.1, 50.0), st.floats(0.05, 12.0)), min_size=1,
                max_size=8),
       st.floats(0.0, 400.0))
def test_travel_is_the_integral_of_the_schedule_and_every_change_is_told(changes, later):
    told: list[tuple[float, float]] = []
    b = Belt(3.0, on_change=lambda t, v: told.append((t, v)))
    now = 0.0
    for dt, v in changes:
        now += dt
        b.plan(now, v)
    t = now + later                       # a belt is asked about the present and the future
    knots = [0.0] + list(np.cumsum([dt for dt, _ in changes]))
    speeds = [3.0] + [v for _, v in changes]
    x = sum(s * (min(t, hi) - lo) for lo, hi, s in zip(knots, knots[1:] + [np.inf], speeds)
            if t > lo)
    assert b.travel(t) == pytest.approx(x, rel=1e-9, abs=1e-9)
    assert b.time_at(b.travel(t)) == pytest.approx(t, rel=1e-9, abs=1e-7)
    b.close()
    assert told == list(zip(knots, speeds))
    assert b.max_speed_in_s == max(speeds)


def test_only_the_schedule_ahead_is_kept():
    b = Belt(3.0)
    for i in range(1, 1000):
        b.plan(float(i), 3.0 + i % 2)
    assert b.held <= 2


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0.1, 30.0), st.floats(0.1, 30.0), st.floats(0.1, 30.0),
                          st.floats(0.5, 6.0), st.floats(0.5, 6.0), st.floats(0.5, 6.0)),
                min_size=1, max_size=12))
def test_plan_of_three_changes_is_plan_and_then_to_the_bit(steps):
    """The output belt's one-call replan (:meth:`Belt.plan` with a third change) leaves
    the very schedule, travel and settled changes that :meth:`Belt.plan` then :meth:`Belt.then`
    leave, whether the last floor has begun or not (each step replans from ``now``)."""
    told_a: list[tuple[float, float]] = []
    told_b: list[tuple[float, float]] = []
    a = Belt(2.0, on_change=lambda t, v: told_a.append((t, v)))
    b = Belt(2.0, on_change=lambda t, v: told_b.append((t, v)))
    now = 0.0
    for gap, to_g, floor, v1, v2, v3 in steps:
        now += gap
        a.plan(now, v1, now + to_g, v2, now + to_g + floor, v3)
        b.plan(now, v1, now + to_g, v2)
        b.then(now + to_g + floor, v3)
        assert (a._t, a._x, a._v) == (b._t, b._x, b._v)
    assert told_a == told_b
    assert (a.max_speed_in_s, a.min_speed_in_s) == (b.max_speed_in_s, b.min_speed_in_s)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0.1, 30.0), st.floats(0.1, 30.0), st.floats(0.1, 30.0),
                          st.floats(0.5, 6.0), st.floats(0.5, 6.0), st.floats(0.5, 6.0),
                          st.floats(0.0, 1.0)),
                min_size=1, max_size=12))
def test_a_belt_replayed_from_its_history_travels_as_it_ran(steps):
    """The belt the animation replays from a run's speed history (:meth:`Belt.of_history`,
    what ``belts.csv`` holds) is where the running belt was at every instant, to the bit, and
    reaches each travel when it did: one rule of a belt's travel for both."""
    told: list[tuple[float, float]] = []
    b = Belt(2.0, on_change=lambda t, v: told.append((t, v)))
    seen = []
    now = 0.0
    for gap, to_g, floor, v1, v2, v3, later in steps:
        t = now + later * gap  # an instant before the replan at now + gap: final by then
        seen.append((t, b.travel(t)))
        now += gap
        b.plan(now, v1, now + to_g, v2, now + to_g + floor, v3)
    b.close()
    replay = Belt.of_history(told)
    assert [(t, replay.travel(t)) for t, _ in seen] == seen
    assert all(replay.time_at(x) == pytest.approx(t, abs=1e-9) for t, x in seen)


def test_only_a_belt_built_stoppable_stops_and_it_stops_where_it_was():
    """Both belts run the same plans alike; only the one built ``stoppable`` (a failure or the
    calendar can stop it) stops.  A replan from 25 s settles the change at 10 s; a stop at 15 s,
    before the first change still held (20 s), starts from the change at 10 s: 30 in + 6 in/s x
    5 s = 60 in, where the belt then stands."""
    plain, stoppable = Belt(3.0), Belt(3.0, stoppable=True)
    for b in (plain, stoppable):
        b.plan(10.0, 6.0, 20.0, 1.5)
        b.plan(25.0, 2.0, 30.0, 3.0)
    assert [plain.travel(t) for t in (20.0, 26.0, 50.0)] == \
        [stoppable.travel(t) for t in (20.0, 26.0, 50.0)] == [90.0, 99.5, 167.5]
    with pytest.raises(RuntimeError):
        plain.stop(15.0)
    stoppable.stop(15.0)
    assert stoppable.travel(15.0) == stoppable.travel(100.0) == 60.0
