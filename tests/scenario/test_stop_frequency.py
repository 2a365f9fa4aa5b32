"""The bound on a run's stops (cell/scenario/failure_spec.py): the mean of a time between stops
with any time beyond the run cut at the run's length, against closed forms, and the renewal
count it bounds."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.stats
from hypothesis import example, given, settings
from hypothesis import strategies as st

from cell.scenario.failure_spec import mean_within


@pytest.mark.parametrize("scale, run_s", [(1e-6, 450.0), (0.3, 0.5), (0.7, 30.0), (600.0, 450.0)])
def test_an_exponentials_mean_within_the_run(scale: float, run_s: float) -> None:
    """E[min(X, T)] = λ (1 − e^(−T/λ)) for X ~ Exp(mean λ); from above, within 2 %."""
    expected = scale * -math.expm1(-run_s / scale)
    got = mean_within(scipy.stats.expon(scale=scale), run_s)
    assert expected <= got <= 1.02 * expected


@pytest.mark.parametrize("sigma, median, run_s", [(8.0, 1e-13, 450.0), (1.0, 0.5, 30.0)])
def test_a_lognormals_mean_within_the_run(sigma: float, median: float, run_s: float) -> None:
    """E[min(X, T)] = e^(μ + σ²/2) Φ((ln T − μ − σ²)/σ) + T (1 − Φ((ln T − μ)/σ)), μ = ln median."""
    mu, phi = math.log(median), scipy.stats.norm.cdf
    expected = math.exp(mu + sigma**2 / 2) * phi((math.log(run_s) - mu - sigma**2) / sigma) \
        + run_s * (1 - phi((math.log(run_s) - mu) / sigma))
    got = mean_within(scipy.stats.lognorm(sigma, scale=median), run_s)
    assert expected <= got <= 1.02 * expected


@settings(max_examples=25, deadline=None)
@given(shape=st.floats(0.3, 3.0), scale=st.floats(0.05, 5.0), run_s=st.floats(5.0, 60.0))
@example(shape=0.3, scale=0.05, run_s=23.75)  # N(T) wide: a path ran out of a fixed number of draws
def test_the_renewal_count_stays_under_twice_the_run_over_the_mean_within(shape: float, scale: float,
                                                                          run_s: float) -> None:
    """E[N(T)] < 2 T / E[min(X, T)] (Wald), the count the floor bounds: Weibull renewals."""
    dist = scipy.stats.weibull_min(shape, scale=scale)
    rng = np.random.default_rng(7)
    bound = 2 * run_s / mean_within(dist, run_s)
    width = int(bound) + 50
    while True:  # enough draws that no path runs out before T (N(T) is wide for a small shape)
        gaps = dist.rvs(size=(400, width), random_state=rng)
        counts = (np.cumsum(gaps, axis=1) <= run_s).sum(axis=1)
        if counts.max() < width:
            break
        width *= 2
    assert counts.mean() < bound
