"""The Weibull's fit at a fixed threshold (``weibull_at``) is the maximum-likelihood estimate:
its likelihood is at least scipy's own fit's (Nelder-Mead) and no step of either parameter
raises it."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from cell.experiments.fit.mle import weibull_at


@pytest.mark.parametrize("seed", range(6))
def test_the_weibull_at_a_threshold_is_the_likeliest(seed):
    rng = np.random.default_rng(seed)
    c0 = rng.uniform(0.4, 5.0)
    x = stats.weibull_min(c0, loc=rng.uniform(0, 10), scale=rng.uniform(1, 30)).rvs(
        int(rng.integers(20, 1500)), random_state=rng)
    loc = float(x.min()) * rng.uniform(0.0, 0.999)

    def ll(c, scale):
        return float(stats.weibull_min.logpdf(x, c, loc, scale).sum())

    c, at, scale = weibull_at(x, loc)
    assert at == loc
    best = ll(c, scale)
    assert best >= ll(*np.asarray(stats.weibull_min.fit(x, floc=loc))[[0, 2]]) - 1e-9 * abs(best)
    for dc, ds in ((1, 0), (-1, 0), (0, 1), (0, -1)):
        assert ll(c * (1 + 1e-6 * dc), scale * (1 + 1e-6 * ds)) <= best


def test_data_at_the_threshold_or_all_equal_is_refused():
    with pytest.raises(ValueError):
        weibull_at(np.array([1.0, 2.0, 3.0]), 1.0)
    with pytest.raises(ValueError):
        weibull_at(np.array([2.0, 2.0, 2.0]), 0.0)
