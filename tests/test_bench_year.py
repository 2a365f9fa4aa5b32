"""The bench's year-long figure with wear on (cell.bench.parts_per_second_year)."""

from __future__ import annotations

import math

import pytest

from cell import bench
from cell.scenario import default_scenario


def test_the_year_figure_runs_the_long_run_with_wear_on(monkeypatch) -> None:
    seen = []
    real = bench._streamed

    def spy(scenario):  # noqa: ANN001, ANN202
        seen.append(scenario)
        return real(scenario)

    monkeypatch.setattr(bench, "_streamed", spy)
    rate = bench.parts_per_second_year(default_scenario(), parts=400)
    assert math.isfinite(rate) and rate > 0
    (s,) = seen
    assert s.wear.enabled and s.run.parts == 400
    assert bench.YEAR_PARTS * 22.586 / 3600 == pytest.approx(4000, rel=1e-3)
