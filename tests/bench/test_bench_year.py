"""The bench's year-long figure with failures and wear on (cell.bench.throughput.parts_per_second_year)."""

from __future__ import annotations

import math

from cell.bench import throughput as bench
from cell.scenario.schema import default_scenario


def test_the_year_figure_runs_with_failures_and_wear_on(monkeypatch) -> None:
    """The figure is parts arrived per second of one run of the given hours, with every
    piece of equipment able to fail and the robot's clock counting wear."""
    seen = []
    real = bench._streamed

    def spy(scenario):  # noqa: ANN001, ANN202
        seen.append(result := real(scenario))
        seen.append(scenario)
        return result

    monkeypatch.setattr(bench, "_streamed", spy)
    rate = bench.parts_per_second_year(default_scenario(), hours=3.0)
    result, s = seen[-2:]  # the timed run (after a one-hour warm-up of the same scenario)
    assert math.isfinite(rate) and rate > 0
    assert s.wear.enabled and s.run.hours == 3.0
    assert all(getattr(s.failures, name) is not None
               for name in ("robot", "input_belt", "output_belt", "sensor"))
    assert result.wear is not None  # the robot's clock counted wear
    assert 3600 * 3 / 23.5 < result.summary.parts_arrived < 3600 * 3 / 21.5
    assert bench.YEAR_H == 250 * 16
