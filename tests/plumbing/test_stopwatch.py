"""The benchmarks' timer (cell.plumbing.stopwatch)."""

from __future__ import annotations

import itertools

from cell.plumbing import stopwatch


def test_best_seconds_is_the_shortest_of_the_calls(monkeypatch):
    # a clock read twice a call: the calls take 3, 1 and 2 s
    ticks = iter([0.0, 3.0, 10.0, 11.0, 20.0, 22.0])
    monkeypatch.setattr(stopwatch.time, "perf_counter", lambda: next(ticks))
    calls = itertools.count()
    assert stopwatch.best_seconds(lambda: next(calls), 3) == 1.0
    assert next(calls) == 3
