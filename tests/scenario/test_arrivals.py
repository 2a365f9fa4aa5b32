"""The parts supply (cell.scenario.arrivals): eq. 6.9, scipy's moments, traces, common random numbers."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import scipy.stats

from cell.plumbing.errors import ScenarioError
from cell.scenario.arrivals import (
    FEEDER_STREAM,
    MAX_INTERARRIVAL_S,
    check_arrivals,
    interarrival_times,
    stream,
)
from cell.scenario.schema import ArrivalSettings as Arrivals
from cell.scenario.schema import default_scenario

WEIBULL = scipy.stats.weibull_min(1 / 0.2038, loc=17.6019, scale=5.4342)


def test_default_is_eq_6_9_by_inverse_cdf():
    n, seed = 1000, 11
    t = interarrival_times(Arrivals(), n, seed)
    u = stream(seed, FEEDER_STREAM).random(n)
    eq_6_9 = 17.6019 + 5.4342 * (-np.log(1.0 - u)) ** 0.2038
    np.testing.assert_allclose(t, eq_6_9, rtol=1e-9)


def test_weibull_moments_match_scipy_and_the_thesis():
    t = interarrival_times(Arrivals(), 40_000, 3)
    mean, sd = WEIBULL.mean(), WEIBULL.std()
    assert mean == pytest.approx(22.586, abs=1e-3)     # docs/model.md (thesis quotes 22.5872)
    assert sd == pytest.approx(1.16, abs=5e-3)
    assert abs(t.mean() - mean) < 4 * sd / np.sqrt(t.size)
    assert t.std() == pytest.approx(sd, rel=0.03)
    assert t.min() >= 17.6019                          # the location parameter


def test_any_scipy_distribution_by_name():
    a = Arrivals(distribution="gamma", params={"a": 9.0, "loc": 10.0, "scale": 1.4})
    t = interarrival_times(a, 40_000, 5)
    ref = scipy.stats.gamma(9.0, loc=10.0, scale=1.4)
    assert abs(t.mean() - ref.mean()) < 4 * ref.std() / np.sqrt(t.size)


def test_seed_sequence_is_not_consumed():
    root = np.random.SeedSequence(1234)
    a = interarrival_times(Arrivals(), 50, root)
    b = interarrival_times(Arrivals(), 50, root)
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(a, interarrival_times(Arrivals(), 50, 1234))
    assert not np.array_equal(a, interarrival_times(Arrivals(), 50, 1235))
    child = root.spawn(2)[1]
    assert not np.array_equal(a, interarrival_times(Arrivals(), 50, child))


def test_trace_is_replayed_in_order_and_repeats(tmp_path):
    (tmp_path / "trace.csv").write_text("interarrival_s\n20.5\n23.25\n21.0\n")
    a = Arrivals(trace_csv="trace.csv")
    t = interarrival_times(a, 7, 99, tmp_path)
    assert t.tolist() == [20.5, 23.25, 21.0, 20.5, 23.25, 21.0, 20.5]


def test_both_policies_see_the_same_parts():
    from cell.sim.simulation import simulate

    s = default_scenario().with_overrides({"run.parts": 60})
    seed = np.random.SeedSequence(77)
    a = simulate(s, seed=seed).parts
    b = simulate(s.with_overrides({"controller.policy": "non-adaptive"}), seed=seed).parts
    np.testing.assert_array_equal(a["interarrival_s"], b["interarrival_s"])
    np.testing.assert_array_equal(a["arrival_s"], b["arrival_s"])


def test_a_mean_just_over_the_limit_is_shown_over_it(tmp_path):
    """A mean of 1,000,000.02 s is refused against the 1e6 s limit; the message shows it
    with enough digits to be over the limit, not '1e+06 s; at most 1e+06 s'."""
    spec = SimpleNamespace(distribution="expon", params={"loc": MAX_INTERARRIVAL_S, "scale": 0.02},
                           trace_csv=None, mean_s=None, cv=None, profile=None)
    with pytest.raises(ScenarioError) as err:
        check_arrivals(spec, tmp_path, "s.yaml")
    assert "would be 1000000.02 s; at most 1e+06 s" in err.value.why


@pytest.mark.parametrize("distribution, params, words", [
    ("gamma", {"c": 4.9, "loc": 17.6, "scale": 5.4},
     "arrivals.distribution gamma takes a, loc, scale, not c (weibull_min's): give arrivals.params "
     "for gamma, or arrivals.mean_s and arrivals.cv"),
    ("weibull_min", {"s": 0.5, "loc": 17.6, "scale": 5.4},
     "arrivals.distribution weibull_min takes c, loc, scale, not s (lognorm's): give"),
    ("gamma", {"loc": 17.6, "scale": 5.4}, "gamma takes a, loc, scale, a missing: give arrivals.params"),
    ("norm", {"c": 4.9, "loc": 17.6, "scale": 5.4},
     "norm takes loc, scale, not c (weibull_min's): give arrivals.params for norm"),
])
def test_parameters_of_another_family_are_named_with_the_fix(tmp_path, distribution, params, words):
    """Changing only the distribution (--set arrivals.distribution=gamma on the baseline) leaves
    the Weibull's c: the line says whose parameters they are and what to give, not scipy's
    '_parse_args() got an unexpected keyword argument'."""
    spec = SimpleNamespace(distribution=distribution, params=params, trace_csv=None, mean_s=None,
                           cv=None, profile=None)
    with pytest.raises(ScenarioError) as err:
        check_arrivals(spec, tmp_path, "s.yaml")
    assert err.value.key == "arrivals.params" and words in err.value.why, err.value.why
    assert "_parse_args" not in str(err.value) and (distribution != "norm" or "mean_s" not in err.value.why)
