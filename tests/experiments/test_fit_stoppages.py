"""``cell fit`` on a log of part times with a line's stoppages among the gaps (issue 24): the
stoppages are flagged with their count and size, ``--max-gap`` or ``--drop-outliers`` leaves
them out (and the block says so) and then recovers the generating distribution; each fit's
mean and sd stand beside the data's; a fit more than 10 % off them carries a caution; a
timestamp column without ``--times`` gets the hint; the figure is in seconds, on the body of
the data."""

from __future__ import annotations

import argparse
import math
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy import special, stats

from cell.cli.fit import add_arguments
from cell.cli.fit import main as cmd_fit
from cell.experiments.fit.choice import caution
from cell.experiments.fit.figure import figure
from cell.experiments.fit.gaps import far_out, fence, flagged, leave_out
from cell.experiments.fit.mle import Fit
from cell.plumbing.errors import ScenarioError
from cell.scenario.schema import load_scenario
from tests.prose import in_order

# Thesis eq. 6.9, the generating distribution: T = 17.6019 + 5.4342 (-ln(1 - u))^0.2038.
C, LOC, SCALE = 1 / 0.2038, 17.6019, 5.4342
#: Its mean and sd in closed form: loc + scale Γ(1 + 1/c), scale √(Γ(1 + 2/c) − Γ(1 + 1/c)²).
MEAN = LOC + SCALE * special.gamma(1 + 1 / C)
SD = SCALE * math.sqrt(special.gamma(1 + 2 / C) - special.gamma(1 + 1 / C) ** 2)
STOPS_S = [900.0, 1500.0, 2400.0, 3300.0, 600.0]  # five stoppages, 10 to 55 min


def parse(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="cell fit")
    add_arguments(parser)
    return parser.parse_args(list(argv))


def log_with_stoppages(path: Path, n: int = 800, seed: int = 5) -> np.ndarray:
    """A log of n + 1 part times, ISO date-times to the millisecond, whose gaps are eq. 6.9's
    draws (by its inverse cdf) with the stoppages added to five of them; the gaps as logged."""
    rng = np.random.default_rng(seed)
    gaps = LOC + SCALE * (-np.log1p(-rng.random(n))) ** (1 / C)
    gaps[rng.choice(n, len(STOPS_S), replace=False)] += STOPS_S
    ms = np.round(np.concatenate([[0.0], np.cumsum(gaps)]) * 1000).astype(np.int64)
    start = np.datetime64("2026-03-02T06:00:00.000")
    stamps = [str(start + np.timedelta64(int(v), "ms")).replace("T", " ") for v in ms]
    path.write_text("part,time\n" + "".join(f"{i},{s}\n" for i, s in enumerate(stamps)))
    return np.diff(ms) / 1000.0


def test_stoppages_are_flagged_with_their_count_and_size(tmp_path: Path, capsys):
    gaps = log_with_stoppages(tmp_path / "log.csv")
    assert cmd_fit(parse(str(tmp_path / "log.csv"), "--column", "time", "--times",
                         "--families", "gamma,expon")) == 0
    err = capsys.readouterr().err
    flag = next(line for line in err.splitlines() if "far out of the body" in line)
    limit = fence(gaps)
    assert limit < 40.0  # the fence sits just above the flow's gaps, far below any stoppage
    far = gaps[gaps > limit]
    assert far.size == len(STOPS_S)
    assert flag.startswith(f"cell: warning: {far.size} of {gaps.size} gaps ")
    assert in_order(flag, f"Q3 + 3 IQR = {limit:.4g} s:", f"{far.min():.4g} to {far.max():.4g} s",
                    f"{far.sum():.4g} s in all")
    assert "--max-gap S or --drop-outliers" in flag


@pytest.mark.parametrize("option", [["--max-gap", "120"], ["--drop-outliers"]])
def test_leaving_the_stoppages_out_recovers_the_generating_distribution(tmp_path: Path, capsys, option):
    log_with_stoppages(tmp_path / "log.csv")
    out = tmp_path / "arrivals.yaml"
    assert cmd_fit(parse(str(tmp_path / "log.csv"), "--column", "time", "--times", *option,
                         "--families", "weibull_min,gamma", "--out", str(out))) == 0
    printed = capsys.readouterr()
    assert "far out of the body" not in printed.err and "CAUTION" not in out.read_text()
    comments = " ".join(line[2:] for line in out.read_text().splitlines() if line.startswith("# "))
    assert "left out: 5 of 800 gaps longer than" in comments and f"({option[0]}" in comments
    assert "the fit is of the other 795" in comments
    arrivals = load_scenario(out).arrivals  # the block is one a run accepts
    fitted = getattr(stats, arrivals.distribution)(**arrivals.params)
    assert fitted.mean() == pytest.approx(MEAN, rel=0.01)
    assert fitted.std() == pytest.approx(SD, rel=0.05)
    t = np.linspace(LOC, LOC + 3 * SCALE, 400)
    true_cdf = 1.0 - np.exp(-(((t - LOC) / SCALE) ** C))  # eq. 6.9's cdf in closed form
    assert np.max(np.abs(fitted.cdf(t) - true_cdf)) < 0.03


def test_fitting_the_stoppages_gives_a_caution(tmp_path: Path, capsys):
    """With them in, no family fits: the one written gets a CAUTION and a warning."""
    log_with_stoppages(tmp_path / "log.csv")
    out = tmp_path / "arrivals.yaml"
    assert cmd_fit(parse(str(tmp_path / "log.csv"), "--column", "time", "--times",
                         "--families", "gamma,expon", "--out", str(out))) == 0
    err = capsys.readouterr().err
    assert "does not stand for these data" in err
    assert "# CAUTION: the fitted" in out.read_text()


def test_the_table_sets_each_fits_mean_and_sd_beside_the_datas(tmp_path: Path, capsys):
    gaps = log_with_stoppages(tmp_path / "log.csv", n=300)
    assert cmd_fit(parse(str(tmp_path / "log.csv"), "--column", "time", "--times", "--max-gap", "120",
                         "--families", "gamma,expon,norm")) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[:5] == ["#", "rank", "family", "parameters", "mean"]
    kept = gaps[gaps <= 120]
    data = lines[1].split()
    assert data[1:5] == ["data", "n", "=", str(kept.size)]
    assert float(data[5]) == pytest.approx(kept.mean(), rel=1e-3)
    assert float(data[6]) == pytest.approx(kept.std(ddof=1), rel=1e-3)
    rows = {line.split()[2]: line for line in lines[2:5]}
    block = yaml.safe_load("\n".join(line for line in lines if not line.startswith("#")))
    for family, row in rows.items():
        params = dict(re.findall(r"(\w+)=([-+.e\d]+)", row))
        d = getattr(stats, family)(**{k: float(v) for k, v in params.items()})
        mean, sd = (float(v) for v in re.split(r"\s{2,}", row[1:].strip())[3:5])  # columns: 2+ spaces
        assert mean == pytest.approx(d.mean(), rel=2e-3) and sd == pytest.approx(d.std(), rel=2e-3)
    assert rows[block["arrivals"]["distribution"]].endswith("written")
    assert rows["norm"].endswith("allows negative times")


def test_a_fit_more_than_ten_percent_off_is_cautioned() -> None:
    """12 % off the sd: on 2,000 values that is beyond the sample's own error and the fit does not
    stand; on 25 values it is within it, and the caution says so. Within 10 %: none."""
    rng = np.random.default_rng(1)
    big, small = (stats.gamma(a=9.0, scale=2.0).rvs(n, random_state=rng) for n in (2000, 25))
    for x in (big, small):
        a = (x.mean() / (1.12 * x.std(ddof=1))) ** 2  # the data's mean, sd 12 % above theirs
        wide = Fit("gamma", {"a": a, "scale": x.mean() / a}, 0.05, 0.5, 0.0, 0.0)
        said = caution(wide, x)
        assert said.startswith("the fitted gamma")
        if x is big:
            assert "does not stand for these data" in said
        else:
            assert "more than 10% off the data's" in said and "within the sampling error of 25" in said
    a = (big.mean() / (1.05 * big.std(ddof=1))) ** 2  # 5 % off, within the sampling error
    assert caution(Fit("gamma", {"a": a, "scale": big.mean() / a}, 0.05, 0.5, 0.0, 0.0), big) == ""


def test_iso_timestamps_without_times_get_the_hint(tmp_path: Path):
    log_with_stoppages(tmp_path / "log.csv", n=30)
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(tmp_path / "log.csv"), "--column", "time"))
    assert err.value.key == "time[line 2]" and err.value.value == "2026-03-02 06:00:00.000"
    assert "looks like timestamps: use --times" in err.value.why


def test_the_figure_is_in_seconds_on_the_body_of_the_data(tmp_path: Path):
    gaps = log_with_stoppages(tmp_path / "log.csv", n=300)
    fit = Fit("weibull_min", {"c": C, "loc": LOC, "scale": SCALE}, 0.05, 0.5, 0.0, 0.0)
    fig = figure(gaps, [fit], xlabel="gap between the arrival times in time (s)")
    ax = fig.axes[0]
    lo, hi = ax.get_xlim()
    assert ax.get_xlabel().endswith("(s)") and ax.get_ylabel() == "density (1/s)"
    assert lo <= gaps.min() and gaps[gaps < 100].max() <= hi < 40.0  # not stretched to 3300 s
    assert ax.get_title(loc="left").startswith("5 of 300 values beyond")


def test_far_out_and_leave_out_by_hand() -> None:
    x = np.array([10.0] * 10 + [11.0] * 10 + [12.0] * 10 + [100.0, 500.0])
    q1, q3 = np.percentile(x, [25, 75])
    assert fence(x) == pytest.approx(q3 + 3 * (q3 - q1))
    tail = far_out(x)
    assert (tail.found, tail.least, tail.largest, tail.total) == (2, 100.0, 500.0, 600.0)
    assert tail.share == pytest.approx(600.0 / x.sum()) and flagged(tail) is False  # 2 of 32 > 5 %
    kept, said = leave_out(x, 200.0, "--max-gap 200")
    assert kept.size == 31 and in_order(said, "left out: 1 of 32 gaps", "200 s (--max-gap 200)")
    kept, said = leave_out(x, 1000.0, "--max-gap 1000")
    assert kept.size == x.size and said == ""
