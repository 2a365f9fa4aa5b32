"""Statistics for experiments, checked against scipy called directly, closed forms
and synthetic data with known answers (never against the module's own output)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

from cell.experiments.stats import (
    next_round,
    no_variation,
    paired_difference,
    precision_reached,
    relative_half_width,
    summarise,
)
from cell.sim.warmup import mser, mser5, mser_statistic


# --------------------------------------------------------------------------- summarise
def test_summarise_matches_textbook_closed_form():
    # x = 2, 4, 4, 4, 5, 5, 7, 9: mean 5, s^2 = 32/7, t(0.975, 7) = 2.3646242515927...
    x = np.array([2, 4, 4, 4, 5, 5, 7, 9], dtype=float)
    s = summarise(x)
    half = 2.3646242515927 * math.sqrt(32 / 7) / math.sqrt(8)
    assert s["n"] == 8
    assert s["mean"] == pytest.approx(5.0)
    assert s["sd"] == pytest.approx(math.sqrt(32 / 7))
    assert s["ci_low"] == pytest.approx(5.0 - half, rel=1e-12)
    assert s["ci_high"] == pytest.approx(5.0 + half, rel=1e-12)
    # Percentiles of the single values, linear interpolation between order statistics:
    # position 0.025 * 7 = 0.175 -> 2 + 0.175 * 2; position 0.975 * 7 = 6.825 -> 7 + 0.825 * 2.
    assert s["run_p2_5"] == pytest.approx(2.35)
    assert s["run_p97_5"] == pytest.approx(8.65)
    assert set(s) == {"n", "mean", "sd", "ci_low", "ci_high", "run_p2_5", "run_p97_5"}


@pytest.mark.parametrize("confidence", [0.90, 0.95, 0.99])
def test_summarise_matches_scipy(confidence):
    x = np.random.default_rng(7).gamma(3.0, 2.0, size=37)
    ci = stats.ttest_1samp(x, 0.0).confidence_interval(confidence)
    s = summarise(x, confidence)
    assert (s["ci_low"], s["ci_high"]) == pytest.approx((ci.low, ci.high), rel=1e-12)


def test_summarise_drops_nans():
    s = summarise([1.0, np.nan, 2.0, 3.0, np.nan])
    assert s["n"] == 3 and s["mean"] == pytest.approx(2.0)
    ci = stats.ttest_1samp([1.0, 2.0, 3.0], 0.0).confidence_interval()
    assert (s["ci_low"], s["ci_high"]) == pytest.approx((ci.low, ci.high))


def test_summarise_edge_cases():
    empty = summarise([np.nan])
    assert empty["n"] == 0 and all(math.isnan(v) for k, v in empty.items() if k != "n")
    one = summarise([4.0])
    assert one["n"] == 1 and one["mean"] == 4.0
    assert math.isnan(one["sd"]) and math.isnan(one["ci_low"]) and math.isnan(one["ci_high"])
    flat = summarise([3.5] * 6)
    assert flat["sd"] == 0.0 and flat["ci_low"] == flat["ci_high"] == 3.5
    assert no_variation([3.5] * 6) and no_variation([3.5, np.nan, 3.5])
    assert not no_variation([3.5]) and not no_variation([3.5, 3.6]) and not no_variation([])
    tiny = summarise([0.0, 1e-300])  # differ, but the squared spread underflows: treated as none
    assert tiny["ci_low"] == tiny["ci_high"] == tiny["mean"] and no_variation([0.0, 1e-300])


#: Equal values whose numpy mean misses them by a rounding (so np.std is about 1e-16 of them).
ROUNDED = [(0.1, 3), (1 / 3, 10), (22.5872, 200), (159.7, 200)]


def with_nans(value: float, n: int) -> np.ndarray:
    """``n`` copies of ``value`` with a NaN after every third."""
    return np.array([v for _ in range(n) for v in ([value] + [np.nan] * (_ % 3 == 2))])


@pytest.mark.parametrize(("value", "n"), ROUNDED)
def test_summarise_all_equal_is_the_value_with_no_spread(value, n):
    x = with_nans(value, n)
    assert np.mean(x[~np.isnan(x)]) != value  # the trap: the plain mean is off
    s = summarise(x)
    assert s["n"] == n and s["mean"] == value and s["sd"] == 0.0
    assert s["ci_low"] == s["ci_high"] == s["run_p2_5"] == s["run_p97_5"] == value
    assert no_variation(x) and relative_half_width(x) == 0.0
    assert precision_reached({"p": x}, 1e-300, min_n=n) == {"p": True}


@pytest.mark.parametrize(("value", "n"), ROUNDED)
def test_paired_all_equal_differences_are_exact_without_a_p_value(value, n):
    a, b = np.full(n + 2, value), np.zeros(n + 2)  # a - b is exactly a
    a[0] = b[1] = np.nan  # a NaN on either side drops the pair
    assert np.mean(a[2:] - b[2:]) != value
    p = paired_difference(a, b)
    assert p["n"] == n and p["mean"] == value and p["sd"] == 0.0
    assert p["ci_low"] == p["ci_high"] == value and math.isnan(p["p_value"])


def test_summarise_rejects_bad_confidence():
    with pytest.raises(ValueError):
        summarise([1.0, 2.0], confidence=95)


def test_coverage_of_the_t_interval_is_nominal():
    """1,000 intervals from n = 20 normal draws: about 95 % cover the true mean.

    Binomial sd of the fraction is sqrt(0.95 * 0.05 / 1000) = 0.0069, so
    0.93-0.97 is about +-3 sd."""
    rng = np.random.default_rng(20240501)
    mu = 10.0
    draws = rng.normal(mu, 3.0, size=(1000, 20))
    covered = [s["ci_low"] <= mu <= s["ci_high"] for s in map(summarise, draws)]
    assert 0.93 <= np.mean(covered) <= 0.97


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(min_value=-1e6, max_value=1e6, allow_nan=False), min_size=2, max_size=60)
       .filter(lambda v: len(set(v)) > 1 and np.std(v, ddof=1) > 0))  # a spread, not underflowing
def test_summarise_properties(values):
    s = summarise(values)
    assert not no_variation(values)
    assert s["n"] == len(values)
    assert all(math.isfinite(v) for v in s.values())
    assert s["ci_low"] <= s["mean"] <= s["ci_high"]
    assert min(values) <= s["run_p2_5"] <= s["run_p97_5"] <= max(values)
    assert s["sd"] > 0.0


# --------------------------------------------------------------------------- paired
def test_paired_matches_scipy_and_one_sample_ci_of_differences():
    rng = np.random.default_rng(11)
    common = rng.exponential(5.0, size=30)  # the shared random numbers
    a = common + rng.normal(0.0, 0.5, size=30) + 0.4
    b = common + rng.normal(0.0, 0.5, size=30)
    p = paired_difference(a, b)
    ref = stats.ttest_rel(a, b)
    ci = ref.confidence_interval()
    assert (p["ci_low"], p["ci_high"]) == pytest.approx((ci.low, ci.high), rel=1e-12)
    assert p["p_value"] == pytest.approx(ref.pvalue, rel=1e-12)
    one = summarise(a - b)
    assert (p["ci_low"], p["ci_high"]) == pytest.approx((one["ci_low"], one["ci_high"]), rel=1e-12)
    assert p["mean"] == pytest.approx(np.mean(a - b)) and p["sd"] == pytest.approx(np.std(a - b, ddof=1))
    # Common random numbers: the paired interval is much narrower than Welch's unpaired one.
    welch = stats.ttest_ind(a, b, equal_var=False).confidence_interval()
    assert p["ci_high"] - p["ci_low"] < 0.5 * (welch.high - welch.low)


def test_paired_drops_nan_pairs():
    a = [1.0, 2.0, np.nan, 4.0, 5.5]
    b = [0.5, np.nan, 3.0, 3.0, 5.0]
    p = paired_difference(a, b)
    ci = stats.ttest_rel([1.0, 4.0, 5.5], [0.5, 3.0, 5.0]).confidence_interval()
    assert p["n"] == 3 and (p["ci_low"], p["ci_high"]) == pytest.approx((ci.low, ci.high))


def test_paired_identical_inputs_have_no_variation():
    a = np.array([3.0, 1.0, 4.0, 1.0, 5.0])
    p = paired_difference(a, a.copy())
    assert p["mean"] == p["ci_low"] == p["ci_high"] == 0.0 and p["sd"] == 0.0
    assert no_variation(a - a)


@pytest.mark.filterwarnings("ignore:Precision loss:RuntimeWarning")  # scipy, on near-equal differences
@settings(max_examples=100, deadline=None)
@given(st.lists(st.tuples(st.floats(-1e6, 1e6), st.floats(-1e6, 1e6)), min_size=2, max_size=40)
       .filter(lambda pairs: len({a - b for a, b in pairs}) > 1
               and np.std([a - b for a, b in pairs], ddof=1) > 0))
def test_paired_properties(pairs):
    a, b = (np.array(v) for v in zip(*pairs))
    p = paired_difference(a, b)
    assert p["n"] == len(pairs) and all(math.isfinite(v) for v in p.values())
    assert p["ci_low"] <= p["mean"] <= p["ci_high"] and 0.0 <= p["p_value"] <= 1.0


@given(st.dictionaries(st.integers(0, 9), st.integers(0, 200), min_size=1), st.integers(1, 50),
       st.integers(1, 150), st.data())
def test_next_round_never_overshoots(counts, batch, max_n, data):
    reached = {k: data.draw(st.booleans()) for k in counts}
    need = next_round(counts, reached, batch, max_n)
    for k, n in counts.items():
        assert 0 <= need[k] <= batch
        assert need[k] == 0 if reached[k] or n >= max_n else n + need[k] <= max_n


def test_paired_rejects_unequal_lengths():
    with pytest.raises(ValueError):
        paired_difference([1.0, 2.0], [1.0])


# --------------------------------------------------------------------------- relative half-width
def test_relative_half_width():
    x = np.array([2, 4, 4, 4, 5, 5, 7, 9], dtype=float)
    half = stats.t.ppf(0.975, 7) * math.sqrt(32 / 7) / math.sqrt(8)
    assert relative_half_width(x) == pytest.approx(half / 5.0)
    assert relative_half_width(-x) == pytest.approx(half / 5.0)
    assert relative_half_width([2.0, 2.0, 2.0]) == 0.0
    assert relative_half_width([-1.0, 1.0]) == math.inf
    assert relative_half_width([1.0]) == math.inf


# --------------------------------------------------------------------------- replications to precision
def run_to_precision(streams, precision, batch, min_n, max_n, confidence=0.95):
    """The caller's loop: whole rounds, then the rule; returns final counts and flags."""
    counts = dict.fromkeys(streams, 0)
    reached = dict.fromkeys(streams, False)
    while True:
        need = next_round(counts, reached, batch, max_n)
        if not any(need.values()):
            return counts, reached
        counts = {k: counts[k] + need[k] for k in counts}
        reached = precision_reached({k: streams[k][:counts[k]] for k in streams}, precision,
                                    confidence, min_n=min_n)


def test_stopping_rule_stops_where_the_closed_form_says():
    """Alternating m +- s: at even n the mean is m and the sd s*sqrt(n/(n-1)) exactly,
    so the half-width is t(0.975, n-1) * s / sqrt(n-1)."""
    m, s, p = 100.0, 10.0, 0.02
    x = np.tile([m + s, m - s], 500)
    expected = next(n for n in range(4, 1000, 2) if stats.t.ppf(0.975, n - 1) * s / math.sqrt(n - 1) <= p * m)
    counts, reached = run_to_precision({"x": x}, p, batch=2, min_n=4, max_n=1000)
    assert counts == {"x": expected} and reached == {"x": True}
    assert 98 <= expected <= 106  # roughly (1.98 * 10 / 2)^2 + 1


def test_stopping_rule_on_normal_data_near_the_closed_form():
    mu, sigma, p = 50.0, 5.0, 0.01
    n_star = next(n for n in range(2, 10_000) if stats.t.ppf(0.975, n - 1) * sigma / math.sqrt(n) <= p * mu)
    x = np.random.default_rng(5).normal(mu, sigma, size=5000)
    counts, reached = run_to_precision({"x": x}, p, batch=1, min_n=10, max_n=5000)
    assert reached["x"]
    assert abs(counts["x"] - n_star) <= 0.15 * n_star  # sample sd within ~7 % of sigma


def test_stopping_rule_respects_min_and_max():
    x = np.random.default_rng(6).normal(50.0, 5.0, size=500)
    counts, reached = run_to_precision({"x": x}, 10.0, batch=3, min_n=12, max_n=100)
    assert counts == {"x": 12} and reached == {"x": True}  # precise at once, but not before min_n
    counts, reached = run_to_precision({"x": x}, 1e-4, batch=7, min_n=12, max_n=100)
    assert counts == {"x": 100} and reached == {"x": False}  # never precise: capped, not overshot
    assert next_round({"a": 98, "b": 5}, {"a": False, "b": True}, batch=7, max_n=100) == {"a": 2, "b": 0}


def test_stopping_rule_does_not_depend_on_how_data_arrive():
    rng = np.random.default_rng(8)
    streams = {(i, j): rng.normal(20.0 + i, 1.0 + 2 * j, size=800) for i in range(3) for j in range(3)}
    whole = precision_reached({k: v[:150] for k, v in streams.items()}, 0.03, min_n=10)
    chunked = precision_reached({k: np.concatenate([v[:40], v[40:41], v[41:150]])
                                 for k, v in streams.items()}, 0.03, min_n=10)
    assert whole == chunked and any(whole.values()) and not all(whole.values())
    # Points split between "workers" in any way: the same verdict for each.
    keys = list(streams)
    split = (precision_reached({k: streams[k][:150] for k in keys[::2]}, 0.03, min_n=10)
             | precision_reached({k: streams[k][:150] for k in keys[1::2]}, 0.03, min_n=10))
    assert split == whole
    # With batches of b the loop stops at the first checked n = b, 2b, ... whose prefix is precise.
    # The reference: Student's interval of each prefix, as stats.t.interval(0.95, n - 1, mean,
    # sem) gives it (loc + scale * ppf(q)), with the ppf, mean and standard error (sd with
    # ddof=1 over sqrt(n), from the prefix sums) of every n computed at once.
    n_all = np.arange(2, 801)
    q_lo, q_hi = stats.t.ppf(0.025, n_all - 1), stats.t.ppf(0.975, n_all - 1)
    precise = {}
    for k, v in streams.items():
        mean = np.cumsum(v)[n_all - 1] / n_all
        squares = np.cumsum((v - v.mean()) ** 2)[n_all - 1] - n_all * (mean - v.mean()) ** 2
        sem = np.sqrt(squares / (n_all - 1) / n_all)
        assert sem[[0, 98, -1]] == pytest.approx([stats.sem(v[:n]) for n in (2, 100, 800)], rel=1e-12)
        precise[k] = dict(zip(n_all.tolist(), ((mean + sem * q_hi) - (mean + sem * q_lo)) / 2
                              <= 0.02 * np.abs(mean)))
    for batch in (4, 25):  # batch 1 checks every n by the same rule, 800 rounds
        counts, _ = run_to_precision(streams, 0.02, batch=batch, min_n=10, max_n=800)
        for k in streams:
            checks = [n for n in range(batch, 801, batch) if n >= 10]
            assert counts[k] == next((n for n in checks if precise[k][n]), 800)


def test_precision_reached_validates():
    with pytest.raises(ValueError):
        precision_reached({"x": [1.0, 2.0]}, 0.0)
    with pytest.raises(ValueError):
        precision_reached({"x": [1.0, 2.0]}, 0.1, min_n=1)
    with pytest.raises(ValueError):
        next_round({"x": 1}, {"x": False}, batch=0, max_n=10)


# --------------------------------------------------------------------------- MSER
def test_mser_statistic_matches_its_definition():
    x = np.random.default_rng(9).normal(size=503)
    x[:100] += 2.0
    k = 100  # batches of 5; the last 3 observations are ignored
    z = x[:500].reshape(k, 5).mean(axis=1)
    direct = [np.sum((z[d:] - z[d:].mean()) ** 2) / (k - d) ** 2 for d in range(k // 2 + 1)]
    assert mser_statistic(x, 5) == pytest.approx(direct, rel=1e-9, abs=1e-15)


def test_mser5_finds_the_end_of_a_step_transient():
    """First 500 observations biased by +3 sd, then stationary noise: the truncation
    is never before the bias ends and, in most series, within two batches of it."""
    found = []
    for seed in range(20):
        x = np.random.default_rng(seed).normal(0.0, 1.0, size=5000)
        x[:500] += 3.0
        found.append(mser5(x))
    assert all(f % 5 == 0 for f in found)
    assert min(found) >= 500
    assert np.mean(np.array(found) <= 510) >= 0.8
    assert np.median(found) == 500


def test_mser5_removes_most_of_an_exponential_bias():
    """Bias 10 exp(-t / 100) on unit noise: what is left after truncation moves the
    mean of the remainder by less than two of its standard errors."""
    t = np.arange(5000)
    bias = 10.0 * np.exp(-t / 100.0)
    for seed in range(10):
        d = mser5(np.random.default_rng(seed).normal(size=t.size) + bias)
        assert 100 <= d <= 1000
        assert bias[d:].mean() < 2.0 / math.sqrt(t.size - d)


def test_mser5_truncates_little_of_a_stationary_series():
    found = [mser5(np.random.default_rng(seed).normal(size=5000)) for seed in range(20)]
    assert np.median(found) == 0 and max(found) <= 100  # at most 2 % of the run


def test_mser_short_and_bad_series():
    assert mser5([1.0, 2.0, 3.0]) == 0
    assert mser([5.0, 1.0, 1.0, 1.0], batch=1) in (0, 1)
    with pytest.raises(ValueError):
        mser5([1.0, np.nan] * 10)
    with pytest.raises(ValueError):
        mser([1.0] * 10, batch=0)


def test_mser_needs_no_scipy():
    """`run.warmup_parts: auto` calls MSER on every run: it must not load scipy."""
    import subprocess
    import sys

    code = ("import sys\nfrom cell.sim.warmup import mser5\nmser5([1.0] * 50)\n"
            "print('scipy' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
