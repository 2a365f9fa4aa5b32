"""``cell fit --as time_to_failure --censored COLUMN`` (issue 21): times to failure or repair,
some right-censored (the item still working when last seen), fitted by the censored
likelihood (scipy.stats.CensoredData), written as the ``failures:`` section's block."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy import stats

from cell.cli.fit import add_arguments
from cell.cli.fit import main as cmd_fit
from cell.experiments.fit.censored import censored_loglik, fit_lifetimes, km_distance
from cell.experiments.fit.scenario_check import _scenario_text, scenario_refuses
from cell.plumbing.errors import ScenarioError
from cell.scenario.schema import is_section
from tests.prose import in_order

C, SCALE, CUT_S = 1.5, 1000.0, 800.0  # Weibull life; every unit still running at 800 s is censored


def parse(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="cell fit")
    add_arguments(parser)
    return parser.parse_args(list(argv))


def censored_sample(n: int = 1000, seed: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Weibull(c = 1.5, scale = 1000 s) lives by the inverse cdf, observed up to 800 s (type I
    censoring: S(800) = exp(-0.8^1.5) = 49 % of the units still run then)."""
    life = SCALE * (-np.log1p(-np.random.default_rng(seed).random(n))) ** (1 / C)
    return np.minimum(life, CUT_S), life > CUT_S


def write_log(path: Path, x: np.ndarray, censored: np.ndarray, flags: tuple[str, str] = ("1", "0")) -> Path:
    path.write_text("unit,ttf_s,running\n" + "".join(
        f"{i},{v:.4f},{flags[0] if c else flags[1]}\n" for i, (v, c) in enumerate(zip(x, censored), 1)))
    return path


def test_the_censored_fit_recovers_the_weibull_where_the_naive_fit_is_biased():
    x, censored = censored_sample()
    assert 0.4 < censored.mean() < 0.6
    (fit,) = fit_lifetimes(x, censored, families=("weibull_min",))
    assert fit.params["c"] == pytest.approx(C, rel=0.08)
    assert fit.params["scale"] == pytest.approx(SCALE, rel=0.06)
    assert fit.params["loc"] == 0.0
    # Ignoring the censoring: the censored times taken as failures, or left out.
    (as_failures,) = fit_lifetimes(x, None, families=("weibull_min",))
    (left_out,) = fit_lifetimes(x[~censored], None, families=("weibull_min",))
    for naive in (as_failures, left_out):
        assert naive.params["scale"] < 0.75 * SCALE  # lives far too short
        assert abs(naive.params["c"] / C - 1.0) > 0.3


def test_the_censored_likelihood_is_the_maximum_of_its_closed_form():
    """Σ log f over the failures + Σ log S over the censored (Weibull in closed form), maximal
    at the fit: nudging either parameter lowers it."""
    x, censored = censored_sample(400, seed=8)
    (fit,) = fit_lifetimes(x, censored, families=("weibull_min",))
    c, scale = fit.params["c"], fit.params["scale"]

    def closed(c: float, scale: float) -> float:
        z = x / scale
        logf = np.log(c / scale) + (c - 1) * np.log(z) - z**c
        return float(logf[~censored].sum() - (z[censored] ** c).sum())

    assert fit.loglik == pytest.approx(closed(c, scale), rel=1e-9)
    assert censored_loglik(stats.weibull_min, x, censored, [c, 0.0, scale]) == pytest.approx(fit.loglik)
    for dc, ds in ((1.01, 1), (0.99, 1), (1, 1.01), (1, 0.99)):
        assert closed(c * dc, scale * ds) < fit.loglik


def test_the_distance_to_kaplan_meier_counts_both_sides_of_each_step():
    x, censored = np.array([1.0, 2.0, 3.0, 4.0]), np.array([False, True, False, False])
    # KM: S drops 1/4 at 1, then (after the censored 2) by 1/2 of the two left at 3 and at 4
    km = {1.0: 0.25, 2.0: 0.25, 3.0: 0.625, 4.0: 1.0}
    assert km_distance(x, censored, lambda t: np.array([km[v] for v in t])) == pytest.approx(0.375)
    assert km_distance(x, censored, lambda t: np.ones_like(t)) == pytest.approx(1.0)


def test_cmd_fit_writes_the_failures_block(tmp_path: Path, capsys):
    x, censored = censored_sample(300)
    log = write_log(tmp_path / "ttf.csv", x, censored, ("true", "false"))
    out = tmp_path / "ttf.yaml"
    assert cmd_fit(parse(str(log), "--column", "ttf_s", "--as", "time_to_failure", "--censored", "running",
                         "--families", "weibull_min,expon", "--out", str(out))) == 0
    printed = capsys.readouterr()
    assert printed.err == ""  # no caution: the data's own mean and sd are unknown under censoring
    table = printed.out.splitlines()
    assert "  KM D  " in table[0] and table[1].split()[:7] == [
        "data", "n", "=", "300,", str(int(censored.sum())), "censored", "-"]
    text = out.read_text()
    assert in_order(text.splitlines()[0], "(300 times,", f" {int(censored.sum())} of them right-censored",
                    "by running)")
    assert "scipy.stats.CensoredData" in text and "failures.EQUIPMENT" in text
    block = yaml.safe_load(text)
    assert set(block) == {"time_to_failure"} and block["time_to_failure"]["distribution"] == "weibull_min"
    # by its mean in hours and its shape (issue 33 item 4): the Weibull's mean, scale Γ(1 + 1/c)
    assert block["time_to_failure"]["mean_h"] * 3600 == pytest.approx(
        SCALE * math.gamma(1 + 1 / C), rel=0.15)
    assert block["time_to_failure"]["shape"] == pytest.approx(C, rel=0.08)
    assert scenario_refuses(text, "time_to_failure", out) == ""
    assert (tmp_path / "ttf.png").read_bytes()[:4] == b"\x89PNG"


def test_times_to_repair_without_censoring_are_fitted_as_usual(tmp_path: Path, capsys):
    x = stats.lognorm(s=0.5, scale=600.0).rvs(200, random_state=np.random.default_rng(1))
    log = write_log(tmp_path / "ttr.csv", np.sort(x), np.zeros(x.size, bool))  # sorted: accepted
    assert cmd_fit(parse(str(log), "--column", "ttf_s", "--as", "time_to_repair",
                         "--families", "lognorm,expon")) == 0
    block = yaml.safe_load(capsys.readouterr().out)["time_to_repair"]
    assert block["distribution"] == "lognorm"
    assert block["shape"] == pytest.approx(0.5, rel=0.15) and "params" not in block
    assert block["mean_h"] * 3600 == pytest.approx(float(x.mean()), rel=0.1)


@pytest.mark.skipif(not is_section(("failures",)), reason="this build has no failures: section yet")
def test_a_failures_block_is_validated_under_the_failures_section():
    text = "# c\ntime_to_failure:\n  distribution: weibull_min\n  params: {c: 1.5, loc: 0.0, scale: 900.0}\n"
    scenario = _scenario_text(text, "time_to_failure")
    assert scenario is not None
    robot = yaml.safe_load(scenario)["failures"]["robot"]
    assert robot["time_to_failure"]["params"] == {"c": 1.5, "loc": 0.0, "scale": 900.0}
    assert robot["time_to_repair"]["distribution"] == "weibull_min"
    assert scenario_refuses(text, "time_to_failure", "f.yaml") == ""


@pytest.mark.parametrize("family, params", [
    ("weibull_min", {"c": 1.5, "loc": 0.0, "scale": 143_000.0}),
    ("gamma", {"a": 2.5, "loc": 0.0, "scale": 90.0}),
    ("lognorm", {"s": 0.8, "loc": 0.0, "scale": 600.0}), ("expon", {"loc": 0.0, "scale": 7_200.0})])
def test_a_fitted_time_is_written_by_its_mean_in_hours_and_read_back_as_the_fit(family, params):
    """The block by ``mean_h`` and ``shape`` (seven digits each) is the fitted distribution to
    within the rounding: scipy's mean, sd and each parameter within 1e-6."""
    from cell.experiments.fit.mle import Fit
    from cell.experiments.fit.output import block_yaml
    from cell.scenario.failure_sections import TimeDistribution
    from cell.scenario.failure_spec import frozen

    fit = Fit(family, params, 0.05, 0.5, -100.0, 204.0)
    text = block_yaml(fit, "time_to_failure", "log.csv")
    block = yaml.safe_load(text)["time_to_failure"]
    assert "params" not in block and ("shape" in block) == (family != "expon")
    assert scenario_refuses(text, "time_to_failure", "f.yaml") == ""
    written, fitted = frozen(TimeDistribution(**block)), fit.frozen()
    assert written.mean() == pytest.approx(fitted.mean(), rel=1e-6)
    assert written.std() == pytest.approx(fitted.std(), rel=1e-6)
    assert written.kwds == pytest.approx({k: v for k, v in params.items() if k != "loc"}, rel=1e-6)


def test_a_fit_with_a_location_keeps_scipy_form():
    from cell.experiments.fit.mle import Fit
    from cell.experiments.fit.output import block_yaml

    fit = Fit("weibull_min", {"c": 1.5, "loc": 30.0, "scale": 900.0}, 0.05, 0.5, -100.0, 204.0)
    block = yaml.safe_load(block_yaml(fit, "time_to_repair", "log.csv"))["time_to_repair"]
    assert block["params"] == {"c": 1.5, "loc": 30.0, "scale": 900.0} and "mean_h" not in block


@pytest.mark.parametrize("argv, key, why", [
    (["--censored", "running"], "--censored", "give --as time_to_failure"),
    (["--as", "time_to_failure", "--max-gap", "5"], "--max-gap", "not times to failure or repair"),
    (["--as", "time_to_failure", "--censored", "nope"], "--censored", "needs a column named nope"),
    (["--as", "time_to_failure", "--censored", "unit"], "unit[line 3]", "not a censoring flag"),
])
def test_bad_censoring_options_are_one_line(tmp_path: Path, argv, key, why):
    x, censored = censored_sample(40)
    log = write_log(tmp_path / "ttf.csv", x, censored)
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(log), "--column", "ttf_s", *argv))
    assert err.value.key == key and why in err.value.why
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ttf.csv"]


def test_all_censored_is_refused(tmp_path: Path):
    x = np.full(30, CUT_S)
    log = write_log(tmp_path / "ttf.csv", x, np.ones(30, bool))
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(log), "--column", "ttf_s", "--as", "time_to_failure", "--censored", "running"))
    assert (err.value.key, err.value.value) == ("running", "0 observed of 30")
