"""The run log's derived columns (cell/sim/simulation.py, ``RunLog.column``): the delivery
interval and the feeder's hold are not kept per part but derived after the run, and must be,
to the bit, what the processes wrote on each part (its row of parts.csv), under any arrivals,
either policy, failures or none, and a warm-up."""

from __future__ import annotations

from unittest import mock

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.scenario.schema import load_scenario
from cell.sim import simulation
from tests.sim.test_failures import failure_sections


def _bits(values: np.ndarray) -> list[bytes]:
    return [np.float64(v).tobytes() for v in values]


@settings(max_examples=25, deadline=None)
@given(policy=st.sampled_from(["adaptive", "non-adaptive"]),
       family=st.sampled_from(["gamma", "lognorm", "weibull_min"]),
       cv=st.sampled_from([0.05, 0.5, 1.5]), load=st.floats(0.6, 1.6),
       failures=st.none() | failure_sections(), warmup=st.sampled_from([0, 7]),
       seed=st.integers(0, 1000))
def test_the_derived_columns_are_what_each_part_was_given(policy: str, family: str, cv: float,
                                                          load: float, failures: dict | None,
                                                          warmup: int, seed: int) -> None:
    s = load_scenario("baseline", {
        "run.parts": 90, "run.warmup_parts": warmup, "controller.policy": policy,
        "arrivals.distribution": family, "arrivals.cv": cv, "arrivals.mean_s": 18.0841 * load,
        "controller.nominal_cycle_s": None, "failures": failures, "run.seed": seed})
    logs: list[simulation.RunLog] = []
    summary = simulation._summary

    def kept(cell, log, *rest):  # noqa: ANN001, ANN202 - the run's own log, read after it
        logs.append(log)
        return summary(cell, log, *rest)

    with mock.patch.object(simulation, "_summary", kept):
        res = simulation.simulate(s)
    log, parts = logs[0], res.parts
    assert log.column("part").tolist() == (parts["part"] - 1).tolist()
    for derived, written in (("interval", "delivery_interval_s"), ("feed_delay", "feed_delay_s")):
        assert _bits(log.column(derived)) == _bits(parts[written].to_numpy()), derived
        assert _bits(log.column(derived, warmup)) == _bits(parts[written].to_numpy()[warmup:])
    r, measured = res.summary, parts.iloc[warmup:]
    held = measured["limits"].str.contains("held_at_feeder")
    assert r.feed_delay_max_s == (measured["feed_delay_s"][held].max() if held.any() else 0.0)
    ip = measured["ip_wallclock"].to_numpy()
    assert _bits([r.ip_wallclock]) == _bits([np.nanmean(ip) if np.isfinite(ip).any() else np.nan])
