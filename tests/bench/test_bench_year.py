"""The bench's year-long figure with failures and wear on (cell.bench.throughput.year_with_failures)."""

from __future__ import annotations

import math

from cell.bench import throughput as bench
from cell.scenario.schema import default_scenario


def test_the_year_figure_runs_with_failures_and_wear_on(monkeypatch) -> None:
    """The figure is parts arrived per second of a run of the given hours, with every piece
    of equipment able to fail and the robot's clock counting wear; the ratio is against the
    same number of parts run without failures."""
    seen = []
    real = bench._streamed

    def spy(scenario):  # noqa: ANN001, ANN202
        seen.append(result := real(scenario))
        seen.append(scenario)
        return result

    monkeypatch.setattr(bench, "_streamed", spy)
    rate, ratio = bench.year_with_failures(default_scenario(), hours=3.0, repeats=1)
    result, s, _, plain = seen[-4:]  # the timed runs (after a one-hour warm-up)
    assert math.isfinite(rate) and rate > 0 and math.isfinite(ratio) and ratio > 0
    assert s.wear.enabled and s.run.hours == 3.0
    assert all(getattr(s.failures, name) is not None
               for name in ("robot", "input_belt", "output_belt", "sensor"))
    assert result.wear is not None  # the robot's clock counted wear
    assert 3600 * 3 / 23.5 < result.summary.parts_arrived < 3600 * 3 / 21.5
    assert plain.run.parts == result.summary.parts_arrived and plain.failures is None
    assert not plain.wear.enabled
    assert bench.YEAR_H == 250 * 16
