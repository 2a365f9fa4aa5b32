"""A trace with zero gaps (a line's log stamped to the second, two parts in one second):
the feeder holds the second part until the belt has carried the first clear, parts are
conserved, and every figure of the run is finite, under either policy."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cell.scenario.schema import default_scenario
from tests.scenario.test_any_arrivals import FASTEST, PARTS, bursty_trace, check_run


def stamped_to_the_second(gaps: np.ndarray) -> np.ndarray:
    """The gaps between the arrivals as a log stamped to whole seconds records them."""
    return np.diff(np.floor(np.cumsum(gaps)), prepend=0.0)


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                 HealthCheck.function_scoped_fixture])
@given(load=st.floats(0.7, 1.5), seed=st.integers(0, 2**32 - 1))
def test_zero_gaps_are_held_at_the_feeder_and_every_figure_is_finite(tmp_path: Path, load, seed):
    t = stamped_to_the_second(bursty_trace(np.random.default_rng(seed), load * FASTEST))
    assert (t == 0).sum() >= 2 and t.mean() > 0  # bursts of parts 0.1-0.6 s apart share seconds
    trace = tmp_path / "trace.csv"
    trace.write_text("interarrival_s\n" + "".join(f"{v:.0f}\n" for v in t))
    for policy in ("adaptive", "non-adaptive"):
        s = default_scenario().with_overrides({
            "arrivals.trace_csv": str(trace), "run.parts": PARTS, "controller.policy": policy})
        r = check_run(s, seed)  # conserved, finite, on belts within their limits, parts apart
        p = r.parts
        assert np.array_equal(p["interarrival_s"].to_numpy(), np.resize(t, PARTS))
        # a part due the instant the last was dropped finds the belt not yet clear
        same = p.iloc[1:].loc[p["interarrival_s"].iloc[1:] == 0]
        assert len(same) and (same["feed_delay_s"] > 0).all()
        assert same["limits"].str.contains("held_at_feeder").all()
        assert r.summary.mean_interarrival_s == t.mean()
