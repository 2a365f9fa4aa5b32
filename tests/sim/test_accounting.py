"""The two accountings (cell.sim.accounting) against closed forms and docs/accounting.md's figures."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.stats

from cell.reporting import published as thesis
from cell.sim.accounting import (
    THESIS_SLACK_S,
    parts_per_hr,
    thesis_adaptive,
    thesis_non_adaptive,
    thesis_non_adaptive_held,
)

#: docs/accounting.md's figures for the reconstruction held at the thesis's own miss counts:
#: ideal cycle -> (actual cycle, IP).
DOCS_7_1 = {22.5872: (54.22, 0.3900), 22.0000: (35.64, 0.4390), 21.5000: (29.08, 0.4655),
            21.0000: (25.86, 0.4814), 20.5000: (23.83, 0.4932), 20.0907: (23.03, 0.4984)}
#: Table 7.1 (thesis §7.2, cell.reporting.published) beside them: (ideal cycle, missed, actual cycle, IP,
#: docs actual, docs IP).
TABLE_7_1 = [(ideal, missed, actual, ip, *DOCS_7_1[ideal])
             for ideal, (actual, missed, _, _, ip) in thesis.TABLE_7_1.items()]

WEIBULL = scipy.stats.weibull_min(1 / 0.2038, loc=17.6019, scale=5.4342)  # eq. 6.9


@pytest.fixture(scope="module")
def draws() -> np.ndarray:
    """200 replications of T_1..T_501 from eq. 6.9 (independent of the feeder)."""
    return WEIBULL.ppf(np.random.default_rng(20240601).random((200, 501)))


def test_closed_form_with_known_losses():
    # n parts at T = 24 s except k at 15 s (< C - s): exactly those k are lost.
    n, k, c = 50, 7, 22.5872
    t = np.full(n + 1, 24.0)
    short = np.arange(3, 3 + 2 * k, 2)
    t[short] = 15.0
    r = thesis_non_adaptive(t, c)
    assert r.missed == k
    assert np.array_equal(np.flatnonzero(r.lost), short)
    expected_actual = (t[:-1].sum() + k * c) / (n - k)
    assert r.actual_cycle_s == pytest.approx(expected_actual, rel=1e-12)
    d = np.where(r.lost, t[:-1] + c, t[:-1])
    assert r.mean_ip == pytest.approx(np.mean(t[1:] / (2 * d)), rel=1e-12)


def test_slack_is_the_boundary():
    c = 22.0
    t = np.array([c - THESIS_SLACK_S - 1e-9, c - THESIS_SLACK_S, c, 30.0])
    assert thesis_non_adaptive(t, c).lost.tolist() == [True, False, False]


@pytest.mark.parametrize("row", TABLE_7_1, ids=[str(r[0]) for r in TABLE_7_1])
def test_reconstruction_held_at_thesis_misses_gives_its_figures(draws, row):
    ideal, missed, thesis_actual, thesis_ip, spec_actual, spec_ip = row
    r = thesis_non_adaptive_held(draws, ideal, missed)
    assert (r.missed == missed).all()
    actual, ip = r.actual_cycle_s.mean(), r.mean_ip.mean()
    assert actual == pytest.approx(spec_actual, rel=1.5e-3)
    assert ip == pytest.approx(spec_ip, abs=5e-4)
    # and so the thesis's own Table 7.1 columns
    assert actual == pytest.approx(thesis_actual, rel=2e-3)
    assert ip == pytest.approx(thesis_ip, abs=5e-4)
    assert parts_per_hr(actual) == pytest.approx(3600 / thesis_actual, rel=2e-3)


@pytest.mark.parametrize("row", TABLE_7_1, ids=[str(r[0]) for r in TABLE_7_1])
def test_calibrated_slack_reproduces_the_parts_missed_column(draws, row):
    ideal, missed = row[:2]
    counts = thesis_non_adaptive(draws, ideal).missed
    # the thesis's single run lies within about one run's spread of the mean
    assert abs(counts.mean() - missed) < 1.5 * counts.std() + 1


def test_thesis_adaptive_is_next_arrival_over_motion_time():
    r = thesis_adaptive([23.0, 22.0, 21.0], [22.5, np.nan, 21.0])
    assert r.ip[0] == pytest.approx(23.0 / 22.5)
    assert np.isnan(r.ip[1])
    assert r.actual_cycle_s == pytest.approx(21.75)
    assert r.mean_ip == pytest.approx((23.0 / 22.5 + 1.0) / 2)


def test_counting_arrivals_from_each_pickup_gives_the_thesis_adaptive_figures():
    from cell.sim.accounting import thesis_adaptive_memoryless

    t = WEIBULL.ppf(np.random.default_rng(5).random(400_000))
    shortest = 22.5872 - (9.9855 - 7.4890)            # Table 7.1's minimum cycle, 20.0907
    r = thesis_adaptive_memoryless(t, 22.5872, shortest)
    assert r.mean_ip == pytest.approx(1.0214, abs=3e-3)                      # §7.2
    assert 100 * (22.5872 - r.actual_cycle_s) / 22.5872 == pytest.approx(2.1, abs=0.15)
    assert thesis_adaptive_memoryless([22.5872], 22.5872, shortest).mean_ip == 1.0


@pytest.mark.parametrize("ideal", [22.5872, 21.0])
def test_a_non_adaptive_run_keeps_the_reconstructed_books(ideal):
    """The run's part-by-part bookkeeping (policies/fixed.py) gives what the vectorised
    reconstruction gives on the same draws (cell.sim.accounting.thesis_non_adaptive)."""
    from cell.scenario.arrivals import interarrival_times
    from cell.scenario.schema import load_scenario
    from cell.sim.simulation import simulate

    s = load_scenario("non_adaptive").with_overrides(
        {"run.parts": 300, "run.seed": 11, "controller.ideal_cycle_s": ideal})
    summary = simulate(s, keep_parts=False).summary
    t = interarrival_times(s.arrivals, s.run.parts + 1, s.run.seed, s.base_dir)
    books = thesis_non_adaptive(t, ideal)
    assert summary.parts_missed_thesis == int(books.missed) > 0
    assert summary.actual_cycle_thesis_s == pytest.approx(float(books.actual_cycle_s), rel=1e-12)
    assert summary.ip_thesis == pytest.approx(float(books.mean_ip), rel=1e-12)


def test_every_accounting_is_vectorised_over_replications(draws):
    """A (3, 10) input gives each row's figures, bit for bit what the row gives alone."""
    from cell.sim.accounting import thesis_adaptive_memoryless

    t = draws[:3, :11]
    d = np.where(t[:, 1:] < 20.0, np.nan, np.minimum(t[:, 1:], 22.5872))  # some parts lost
    d[2] = np.nan                                                           # a run with none delivered
    shortest = 20.0907
    for many, one in ((lambda: thesis_adaptive(t[:, 1:], d), lambda i: thesis_adaptive(t[i, 1:], d[i])),
                      (lambda: thesis_adaptive_memoryless(t, 22.5872, shortest),
                       lambda i: thesis_adaptive_memoryless(t[i], 22.5872, shortest)),
                      (lambda: thesis_non_adaptive(t, 21.0), lambda i: thesis_non_adaptive(t[i], 21.0)),
                      (lambda: thesis_non_adaptive_held(t, 21.0, 2),
                       lambda i: thesis_non_adaptive_held(t[i], 21.0, 2))):
        r = many()
        assert np.shape(r.actual_cycle_s) == (3,) and np.shape(r.mean_ip) == (3,)
        for i in range(3):
            alone = one(i)
            np.testing.assert_array_equal(r.actual_cycle_s[i], alone.actual_cycle_s)
            np.testing.assert_array_equal(r.mean_ip[i], alone.mean_ip)
            np.testing.assert_array_equal(r.ip[i], alone.ip)
    assert np.isnan(thesis_adaptive(t[:, 1:], d).actual_cycle_s[2])
    assert isinstance(thesis_adaptive(t[0, 1:], d[0]).actual_cycle_s, float)
    assert np.shape(thesis_adaptive(t[None, :, 1:], d[None]).mean_ip) == (1, 3)
