"""SimResult.belt_histories: the kept belt changes as arrays, the same rows as ``belts``."""

import numpy as np

from cell.scenario.schema import default_scenario
from cell.sim.simulation import simulate


def test_belt_histories_are_the_belts_rows_in_time_order() -> None:
    s = default_scenario().with_overrides({"run.parts": 200, "controller.policy": "adaptive"})
    result = simulate(s)
    histories = result.belt_histories()
    for belt in ("input", "output"):
        rows = histories[belt]
        assert rows.shape[0] > 1
        assert np.array_equal(rows, np.array(result.belts[belt], dtype=float))
        assert np.all(np.diff(rows[:, 0]) >= 0)


def test_belt_histories_empty_when_not_kept() -> None:
    result = simulate(default_scenario().with_overrides({"run.parts": 20}), keep_belts=False)
    assert {b: h.shape for b, h in result.belt_histories().items()} == {
        "input": (0, 2), "output": (0, 2)}
