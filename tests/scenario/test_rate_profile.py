"""Arrivals whose rate changes over a period (``arrivals.profile``, cell.scenario.rate_profile):
a piecewise-constant-rate Poisson process by time-scaling, a renewal process whose mean follows
the profile, common random numbers kept, and bad profiles refused in one line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.stats
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.cli.main import main
from cell.scenario.arrivals import interarrival_times
from cell.scenario.rate_profile import Pieces
from cell.scenario.schema import default_scenario
from tests.refusals import refused_in_one_line

HOUR = 3600.0
#: Rates by hour of a 4-hour period: relative, normalised to a mean of 1 over the period.
RATES = [2.0, 1.0, 1.0, 0.5]
MEAN_S = 30.0


def arrivals(profile: dict | None, **base):
    given_base = base or {"distribution": "expon", "params": {"scale": MEAN_S}}
    overrides = {"arrivals": {**given_base, **({"profile": profile} if profile else {})}}
    return default_scenario().with_overrides(overrides).arrivals


@pytest.fixture(scope="module")
def poisson_counts() -> tuple[np.ndarray, np.ndarray]:
    """Counts of arrivals in each hour-long piece of the first period (the first 4 h of a run
    starting at hour 0), over 600 replications of a piecewise-constant-rate Poisson process;
    and each piece's expected count, rate × length."""
    a = arrivals({"period_h": 4, "rates": RATES})
    counts = []
    for r in range(600):
        t = np.cumsum(interarrival_times(a, 800, np.random.SeedSequence([7, r])))
        assert t[-1] > 4 * HOUR  # the draws cover the period
        counts.append(np.histogram(t, bins=4, range=(0.0, 4 * HOUR))[0])
    relative = np.array(RATES) / np.mean(RATES)  # equal pieces: the time-weighted mean
    return np.array(counts, dtype=float), relative * HOUR / MEAN_S


def test_piece_counts_have_poisson_mean_and_variance_rate_times_length(poisson_counts):
    """A non-homogeneous Poisson process counts N_j ~ Poisson(λ_j L_j) in piece j: mean and
    variance both λ_j L_j (over 600 replications; 4.5 standard errors, the variance's error
    from a Poisson's fourth moment)."""
    counts, expected = poisson_counts
    r = counts.shape[0]
    mean, var = counts.mean(axis=0), counts.var(axis=0, ddof=1)
    np.testing.assert_array_less(np.abs(mean - expected), 4.5 * np.sqrt(expected / r))
    var_se = expected * np.sqrt(2.0 / (r - 1) + 1.0 / (expected * r))
    np.testing.assert_array_less(np.abs(var - expected), 4.5 * var_se)
    assert expected[0] == pytest.approx(4 * expected[3])  # the profile's 2 against 0.5


def test_renewal_gaps_follow_the_profile_in_the_mean():
    """The thesis's Weibull (sd 1.16 s against a mean of 22.59 s) keeps its shape in
    operational time: a gap that lies within one piece is the base gap over the piece's
    relative rate, so its mean is the base mean over that rate."""
    base = {"distribution": "weibull_min", "params": {"c": 1 / 0.2038, "loc": 17.6019,
                                                       "scale": 5.4342}}
    a = arrivals({"period_h": 8, "rates": [1.5, 1, 1, 1, 1, 1, 1, 1]}, **base)
    gaps = interarrival_times(a, 20_000, 3)
    ends = np.cumsum(gaps)
    starts = ends - gaps
    hour_of = (starts % (8 * HOUR)) // HOUR
    whole = hour_of == (ends % (8 * HOUR)) // HOUR  # gaps inside one piece
    weibull = scipy.stats.weibull_min(1 / 0.2038, loc=17.6019, scale=5.4342)
    norm = (1.5 + 7) / 8
    for hour, rate in ((0, 1.5 / norm), (4, 1 / norm)):
        x = gaps[whole & (hour_of == hour)]
        sd = weibull.std() / rate
        assert abs(x.mean() - weibull.mean() / rate) < 4.5 * sd / np.sqrt(x.size)


def test_a_profile_moves_the_same_parts_in_time():
    """One uniform a part, in order: a flat profile leaves the draws as they were (to
    rounding), and any profile keeps the run's parts in the order of its operational times."""
    plain = interarrival_times(arrivals(None), 2000, 5)
    flat = interarrival_times(arrivals({"period_h": 8, "rates": [3, 3]}), 2000, 5)
    np.testing.assert_allclose(np.cumsum(flat), np.cumsum(plain), rtol=1e-12)
    shaped = arrivals({"period_h": 8, "rates": RATES, "run_start_h": 2.5})
    t = np.cumsum(interarrival_times(shaped, 2000, 5))
    np.testing.assert_allclose(Pieces.of(shaped.profile).operational(t), np.cumsum(plain),
                               rtol=1e-9)


rates = st.lists(st.floats(0.01, 100.0), min_size=1, max_size=12)


@settings(max_examples=60, deadline=None)
@given(rates=rates, period=st.floats(0.1, 200.0), phase=st.floats(0.0, 0.999),
       spaced=st.booleans(), s=st.lists(st.floats(0.0, 1e7), min_size=1, max_size=40))
def test_the_integrated_rate_is_inverted_and_averages_one(rates, period, phase, spaced, s):
    """Λ(Λ⁻¹(s)) = s, Λ⁻¹ increasing, and Λ over any whole period is the period (the rates'
    time-weighted mean is 1), for any pieces, equal or not, and any start in the period."""
    starts = None
    if spaced:
        starts = list(np.cumsum(np.r_[0.0, np.full(len(rates) - 1, 1.0)]) * period / len(rates))
    profile = type("P", (), {"period_h": period, "rates": rates, "starts_h": starts,
                             "run_start_h": phase * period})()
    p = Pieces.of(profile)
    s_sorted = np.sort(np.asarray(s))
    t = p.arrival_times(s_sorted)
    assert np.all(np.diff(t) >= 0)
    np.testing.assert_allclose(p.operational(t), s_sorted, rtol=1e-9, atol=1e-6)
    x = np.asarray(s_sorted) / 3.0
    np.testing.assert_allclose(p.operational(x + p.period_s) - p.operational(x), p.period_s,
                               rtol=1e-9)


@pytest.mark.parametrize("profile, key, value", [
    ({"period_h": 8, "rates": [1, 0]}, "arrivals.profile.rates[1]", "0"),
    ({"period_h": 8, "rates": [1, -2]}, "arrivals.profile.rates[1]", "-2"),
    ({"period_h": 8, "rates": []}, "arrivals.profile.rates", "[]"),
    ({"period_h": 8, "rates": [1, 2], "starts_h": [1, 4]}, "arrivals.profile.starts_h[0]", "1"),
    ({"period_h": 8, "rates": [1, 2], "starts_h": [0, 9]}, "arrivals.profile.starts_h[1]", "9"),
    ({"period_h": 8, "rates": [1, 2, 3], "starts_h": [0, 4, 4]},
     "arrivals.profile.starts_h[2]", "4"),
    ({"period_h": 8, "rates": [1, 2], "starts_h": [0]}, "arrivals.profile.starts_h", "[0"),
    ({"period_h": 0, "rates": [1]}, "arrivals.profile.period_h", "0"),
    ({"period_h": 8, "rates": [1], "run_start_h": 8}, "arrivals.profile.run_start_h", "8"),
    ({"rates": [1]}, "arrivals.profile.period_h", ""),
])
def test_a_bad_profile_is_one_line_naming_file_key_and_value(capsys, tmp_path: Path, profile,
                                                             key, value):
    scenario = tmp_path / "s.yaml"
    text = "arrivals:\n  profile: " + str(profile).replace("'", "") + "\n"
    scenario.write_text(text)
    out = tmp_path / "out"
    refused_in_one_line(capsys, ["run", str(scenario), "--out", str(out)], scenario, key, value, out)


def test_a_profile_with_a_trace_is_refused(capsys, tmp_path: Path):
    (tmp_path / "t.csv").write_text("interarrival_s\n20\n25\n")
    scenario = tmp_path / "s.yaml"
    scenario.write_text("arrivals:\n  trace_csv: t.csv\n  profile: {period_h: 8, rates: [2, 1]}\n")
    assert main(["run", str(scenario), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"cell: error: {scenario}: arrivals.profile = ") and "trace_csv" in err
    assert not (tmp_path / "out").exists()


def test_without_a_profile_the_scenario_reads_as_before():
    """A scenario without a profile dumps no ``profile`` key (sweep fingerprints, the thesis's
    own run recognised as such), and one with it keeps it."""
    assert "profile" not in default_scenario().to_dict()["arrivals"]
    with_it = default_scenario().with_overrides({"arrivals.profile": {"period_h": 8, "rates": [1]}})
    assert with_it.to_dict()["arrivals"]["profile"]["period_h"] == 8


def test_cell_run_says_the_arrivals_are_not_stationary(capsys, tmp_path: Path):
    scenario = tmp_path / "s.yaml"
    scenario.write_text("arrivals: {profile: {period_h: 8, rates: [1.2, 1.2, 1, 1, 1, 1, 1, 1]}}\n"
                        "run: {parts: 30}\n")
    assert main(["run", str(scenario), "--out", str(tmp_path / "out")]) == 0
    said = [line for line in capsys.readouterr().out.splitlines() if "arrivals.profile" in line]
    assert len(said) == 1 and "1.14" in said[0] and "0.952" in said[0]  # 1.2 / 1.05, 1 / 1.05
    assert main(["run", "baseline", "--set", "run.parts=30", "--out", str(tmp_path / "b")]) == 0
    assert "arrivals.profile" not in capsys.readouterr().out


@pytest.mark.usefixtures("unlaid")
def test_a_sweep_report_says_the_arrivals_are_not_stationary(sweeps, tmp_path: Path):
    profile = {"period_h": 8, "rates": [2, 1]}
    path = sweeps.write(tmp_path, set={"run.parts": 20, "arrivals.profile": profile},
                        policies=["adaptive"], replications=2, batch=2)
    assert main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--report", str(tmp_path / "rep")]) == 0
    said = [line for line in (tmp_path / "rep" / "report.md").read_text().splitlines()
            if "arrivals.profile" in line]
    assert len(said) == 1 and "1.33" in said[0] and "0.667" in said[0]  # 2 / 1.5, 1 / 1.5
