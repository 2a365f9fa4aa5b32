"""Regime times (cell.sim.robot) against the thesis's figures and a brute-force sum."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.arm.motors import Segment, move_times, velocity_for_time

moves = st.lists(st.tuples(st.one_of(st.just(0.0), st.floats(1e-3, 0.5)), st.floats(0.0, 0.2)),
                 min_size=1, max_size=40)


@settings(max_examples=80, deadline=None)
@given(moves, st.floats(0.05, 20.0))
def test_segment_time_is_the_sum_of_move_times(ms, v):
    ell, tmin = np.array(ms).T
    seg = Segment(ell, tmin)
    brute = float(np.maximum(ell / v, tmin).sum())   # thesis §6.1, move by move
    assert seg.time(v) == pytest.approx(brute, rel=1e-12, abs=1e-12)
    assert seg.floor_s == pytest.approx(tmin.sum())


@settings(max_examples=60, deadline=None)
@given(moves, st.lists(st.sampled_from([0.3, 1.0, 4.3693, 7.0, 2, float("nan")]), max_size=12))
def test_a_segment_that_keeps_its_last_time_answers_as_a_fresh_one(ms, speeds):
    """Asked a run of speeds with repeats (an int among them, and a NaN, which equals nothing),
    the segment gives each the very float a segment never asked before gives (its last answer
    kept: docs/performance.md#last-time); rebuilt from what it saves, it answers the same."""
    ell, tmin = np.array(ms).T
    seg = Segment(ell, tmin)
    again = Segment.of_saved(seg.saved())
    for v in speeds:
        fresh = Segment(ell, tmin).time(v)
        for got in (seg.time(v), again.time(v)):
            assert got == fresh or (np.isnan(got) and np.isnan(fresh))


@settings(max_examples=80, deadline=None)
@given(moves, st.floats(1.0001, 5.0))
def test_segment_velocity_inverts_time(ms, factor):
    ell, tmin = np.array(ms).T
    if ell.sum() == 0:
        return
    seg = Segment(ell, tmin)
    target = max(seg.floor_s, 1e-3) * factor
    v = seg.velocity(target)
    assert seg.time(v) == pytest.approx(target, rel=1e-9)
    assert v == pytest.approx(velocity_for_time(ell, tmin, target), rel=1e-9)


def test_r4_times_are_the_thesis_calibration(timing):
    assert timing.r4_nominal_s == pytest.approx(9.9855, abs=1e-3)   # docs/model.md, §6
    assert timing.r4_min_s == pytest.approx(7.4890, abs=1e-3)       # 75 % of 9.9855
    assert timing.r4.length_in == pytest.approx(35.5424, abs=1e-3)  # docs/model.md
    assert timing.r2.length_in == pytest.approx(4 * np.pi, abs=1e-2)  # 90° at 8 in radius


def test_robot_tracks_the_nominal_belts_and_is_never_faster_than_them(timing):
    assert timing.input_track_max_in_s >= 3.0
    assert timing.output_track_max_in_s >= 2.0
    for v in (1.0, 2.0, 3.0, timing.input_track_max_in_s):
        pre, post = timing.r1_time(v)
        assert pre >= 4.0 / v - 1e-12          # B → LO is 4 in of belt (docs/model.md)
        assert pre - 4.0 / v < 0.05            # only the grasp move may lag the belt
        assert post >= 4.0 / v - 1e-12         # never ahead of the belt's pace
    r1 = sum(timing.r1_time(3.0))
    assert r1 >= 8.0 / 3.0                     # docs/model.md: 2.6667 s at exactly belt speed
    assert sum(timing.r3_time(2.0)) >= 4.0     # docs/model.md: 4.0000 s


def test_regime_floors_are_the_step_table_minima(timing, table):
    t = table
    for name, seg in (("R2", timing.r2), ("R4", timing.r4)):
        rows = t.regime_rows(name)
        assert seg.floor_s == pytest.approx(t.regime_min_time(name))
        v = 2.0
        expected = move_times(t.move_in[rows], t.peak_min_times[rows], v).sum()
        assert seg.time(v) == pytest.approx(expected, rel=1e-12)
