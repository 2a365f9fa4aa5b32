"""``cell fit``: maximum-likelihood input models from traces, their YAML and figure,
and the validation of trace files."""

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
from cell.experiments.fit.budget import subsample
from cell.experiments.fit.mle import Fit, fit_trace
from cell.experiments.fit.output import arrivals_yaml, format_table
from cell.plumbing.errors import ScenarioError

# Thesis eq. 6.9: T = 17.6019 + 5.4342 (-ln(1 - u))^0.2038.
THESIS = {"c": 1 / 0.2038, "loc": 17.6019, "scale": 5.4342}
SEED = 1984
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def thesis_draws(n: int, seed: int = SEED) -> np.ndarray:
    """Eq. 6.9 by its own inverse cdf (not through scipy)."""
    u = np.random.default_rng(seed).random(n)
    return 17.6019 + 5.4342 * (-np.log1p(-u)) ** 0.2038


@pytest.fixture(scope="module")
def thesis_fit():
    x = thesis_draws(2000)
    return x, fit_trace(x)


# --------------------------------------------------------------------------- fitting
def test_recovers_the_thesis_weibull(thesis_fit):
    """At n = 2,000 the three-parameter Weibull MLE scatters (30 seeds): sd of c 6.9 %,
    loc 1.9 %, scale 6.3 % (Cramér-Rao: 6.1, 1.6, 5.5 %; c, loc and scale are
    correlated at |r| > 0.95). So each parameter is checked to 3 sd, and the
    well-determined quantities (mean, sd, cdf) tightly."""
    x, fits = thesis_fit
    best = fits[0]
    assert best.family == "weibull_min"
    p = best.params
    assert set(p) == {"c", "loc", "scale"}
    assert p["c"] == pytest.approx(THESIS["c"], rel=0.18)
    assert p["loc"] == pytest.approx(THESIS["loc"], rel=0.05)
    assert p["scale"] == pytest.approx(THESIS["scale"], rel=0.17)
    true = stats.weibull_min(**THESIS)
    fitted = stats.weibull_min(**p)
    assert fitted.mean() == pytest.approx(true.mean(), rel=0.005)
    assert fitted.std() == pytest.approx(true.std(), rel=0.06)
    grid = np.linspace(17.0, 30.0, 400)
    assert np.max(np.abs(fitted.cdf(grid) - true.cdf(grid))) < 0.02
    assert p["loc"] < x.min()


def test_weibull_fit_is_a_real_maximum(thesis_fit):
    """The MLE's likelihood beats the true parameters' and scipy's own free fit,
    and no nearby point on the threshold ridge does better."""
    x, fits = thesis_fit
    best = fits[0]
    ll = stats.weibull_min.logpdf(x, **best.params).sum()
    assert best.loglik == pytest.approx(ll)
    assert ll >= stats.weibull_min.logpdf(x, **THESIS).sum()
    assert ll >= stats.weibull_min.logpdf(x, *stats.weibull_min.fit(x)).sum() - 1e-6
    for dloc in (-0.05, 0.05):
        loc = best.params["loc"] + dloc
        assert ll >= stats.weibull_min.logpdf(x, *stats.weibull_min.fit(x, floc=loc)).sum()
    assert best.aic == pytest.approx(6.0 - 2.0 * ll)


@pytest.mark.parametrize("family, dist", [
    ("gamma", stats.gamma(a=4.0, loc=10.0, scale=2.0)),
    ("lognorm", stats.lognorm(s=0.5, loc=5.0, scale=10.0)),
])
def test_picks_the_generating_family(family, dist):
    x = dist.rvs(2000, random_state=np.random.default_rng(SEED))
    fits = fit_trace(x)
    assert fits[0].family == family
    fitted = fits[0].frozen()
    assert fitted.mean() == pytest.approx(dist.mean(), rel=0.02)
    assert [f.aic for f in fits] == sorted(f.aic for f in fits)
    ks = stats.kstest(x, fitted.cdf)
    assert (fits[0].statistic, fits[0].p_value) == pytest.approx((ks.statistic, ks.pvalue))


def test_rank_by_ks_and_families():
    x = stats.gamma(a=4.0, loc=10.0, scale=2.0).rvs(300, random_state=np.random.default_rng(1))
    fits = fit_trace(x, families=("expon", "norm", "gamma"), rank_by="ks")
    assert sorted(f.family for f in fits) == ["expon", "gamma", "norm"]
    assert [f.statistic for f in fits] == sorted(f.statistic for f in fits)
    assert fits[-1].family == "expon"
    assert not next(f for f in fits if f.family == "norm").nonnegative
    with pytest.raises(ValueError):
        fit_trace(x, families=("no_such_law",))
    with pytest.raises(ValueError):
        fit_trace(x, rank_by="bic")
    with pytest.raises(ValueError):
        fit_trace([3.0] * 30)


# --------------------------------------------------------------------------- output
def test_yaml_round_trips(thesis_fit):
    _, fits = thesis_fit
    source = "trace.csv, column interarrival_s\n(2000 values)"
    text = arrivals_yaml(fits[0], source)
    comments = [line for line in text.splitlines() if line.startswith("#")]
    assert source.replace("\n", " ") in comments[0]  # the source, on one comment line
    assert "Kolmogorov-Smirnov" in comments[1]
    doc = yaml.safe_load(text)
    arrivals = doc["arrivals"]
    assert arrivals["distribution"] == "weibull_min"
    assert all(isinstance(v, float) for v in arrivals["params"].values())
    rebuilt = getattr(stats, arrivals["distribution"])(**arrivals["params"])
    assert rebuilt.mean() == pytest.approx(fits[0].frozen().mean(), rel=1e-6)


def test_yaml_keeps_small_and_large_parameters():
    fit = Fit("gamma", {"a": 3.0, "loc": 1234567.25, "scale": 1.5e-5}, 0.01, 0.5, 0.0, 6.0)
    params = yaml.safe_load(arrivals_yaml(fit, "t.csv"))["arrivals"]["params"]
    assert params["scale"] == pytest.approx(1.5e-5) and isinstance(params["scale"], float)
    assert abs(params["loc"] - 1234567.25) < 1e-6 * 1.5e-5 * 10  # rounding far below one scale
    assert isinstance(params["a"], float)


def test_table_lists_best_first(thesis_fit):
    _, fits = thesis_fit
    lines = format_table(fits).splitlines()
    assert lines[0].split()[:3] == ["rank", "family", "parameters"]
    assert [line.split()[1] for line in lines[1:len(fits) + 1]] == [f.family for f in fits]
    assert "allows negative times" in next(line for line in lines if " norm " in line)


# --------------------------------------------------------------------------- command line
def parse(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="cell fit")
    add_arguments(parser)
    return parser.parse_args(list(argv))


@pytest.fixture
def trace(tmp_path: Path) -> Path:
    path = tmp_path / "trace.csv"
    x = thesis_draws(400, seed=7)
    path.write_text("part,interarrival_s\n" + "".join(f"{i},{v:.6f}\n" for i, v in enumerate(x, 1)))
    return path


def test_cmd_fit_writes_yaml_and_png(trace: Path, capsys):
    out = trace.parent / "arrivals.yaml"
    assert cmd_fit(parse(str(trace), "--out", str(out))) == 0
    doc = yaml.safe_load(out.read_text())
    assert doc["arrivals"]["distribution"] == "weibull_min"
    assert "trace.csv" in out.read_text().splitlines()[0]
    assert (trace.parent / "arrivals.png").read_bytes()[:8] == PNG_MAGIC
    assert sorted(p.name for p in trace.parent.iterdir()) == ["arrivals.png", "arrivals.yaml", "trace.csv"]
    printed = capsys.readouterr().out
    assert "weibull_min" in printed and "wrote" in printed


def test_cmd_fit_prints_valid_yaml_without_out(trace: Path, capsys):
    assert cmd_fit(parse(str(trace))) == 0
    doc = yaml.safe_load(capsys.readouterr().out)  # the table is printed as comments
    assert set(doc) == {"arrivals"}
    assert sorted(p.name for p in trace.parent.iterdir()) == ["trace.csv"]


def test_cmd_fit_figure_option(trace: Path, capsys):
    fig = trace.parent / "hist.png"
    assert cmd_fit(parse(str(trace), "--figure", str(fig), "--families", "weibull_min,expon")) == 0
    assert fig.read_bytes()[:8] == PNG_MAGIC
    capsys.readouterr()


def _column(values: list[str]) -> str:
    good = [f"{v:.4f}" for v in thesis_draws(30, seed=3)]
    return "interarrival_s\n" + "\n".join(values + good) + "\n"


BAD_TRACES = [
    ("wrong column", "gap_s\n" + "\n".join(["21.0"] * 30) + "\n", "--column", "interarrival_s"),
    ("negative", _column(["21.5", "-3.0"]), "interarrival_s[line 3]", "-3.0"),
    ("zero", _column(["0"]), "interarrival_s[line 2]", "0"),
    ("boolean", _column(["21.5", "22.0", "True"]), "interarrival_s[line 4]", "True"),
    ("text", _column(["abc"]), "interarrival_s[line 2]", "abc"),
    ("infinite", _column(["inf"]), "interarrival_s[line 2]", "inf"),
    ("not a number", _column(["nan"]), "interarrival_s[line 2]", "nan"),
    ("missing cell", "part,interarrival_s\n1,\n" + "".join(f"{i},21.0\n" for i in range(30)),
     "interarrival_s[line 2]", ""),
    ("too few", "interarrival_s\n" + "\n".join(["21.0", "22.5"] * 5) + "\n", "interarrival_s", "10 values"),
    ("all equal", "interarrival_s\n" + "\n".join(["21.0"] * 30) + "\n", "interarrival_s",
     "all 30 values = 21"),
    ("header only", "interarrival_s\n", "interarrival_s", "0 values"),
    ("empty", "", "(file)", None),
    ("ragged", "a,interarrival_s\n1,2,3\n", "(file)", None),
]


@pytest.mark.parametrize("label, text, key, value", BAD_TRACES, ids=[b[0] for b in BAD_TRACES])
def test_bad_traces_are_refused_and_nothing_is_written(tmp_path: Path, label, text, key, value):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    out = tmp_path / "arrivals.yaml"
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(path), "--out", str(out)))
    e = err.value
    assert e.file == str(path) and e.key == key
    if value is not None:
        assert e.value == value
    assert str(e).startswith(f"{path}: {key} = ")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.csv"]


@pytest.mark.parametrize("label, data", [
    ("binary garbage", bytes(range(256)) * 4),
    ("latin-1 text", "interarrival_s\n21,5\u00b0\n".encode("latin-1")),
    ("gzip", b"\x1f\x8b\x08\x00" + bytes(60)),
])
def test_unreadable_files_give_one_clear_error(tmp_path: Path, label, data):
    path = tmp_path / "bad.csv"
    path.write_bytes(data)
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(path), "--out", str(tmp_path / "a.yaml")))
    assert err.value.key == "(file)" and err.value.file == str(path)
    assert "\n" not in str(err.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.csv"]


def test_bad_destinations_and_options(trace: Path):
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(trace.parent / "missing.csv")))
    assert "no such file" in str(err.value)
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(trace), "--out", str(trace.parent / "nodir" / "a.yaml")))
    assert err.value.key == "--out"
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(trace), "--out", str(trace)))
    assert "overwrite the trace" in str(err.value)
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(trace), "--families", "weibull_min,bogus"))
    assert err.value.value == "bogus"
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(trace), "--column", "Interarrival_s"))
    assert err.value.key == "--column" and "(found 'part', 'interarrival_s')" in str(err.value)
    with pytest.raises(ScenarioError):
        cmd_fit(parse(str(trace), "--families", "norm"))  # no family with non-negative support
    assert sorted(p.name for p in trace.parent.iterdir()) == ["trace.csv"]


def test_p_value_is_finite(thesis_fit):
    _, fits = thesis_fit
    assert all(0.0 <= f.p_value <= 1.0 and math.isfinite(f.aic) for f in fits)


# --------------------------------------------------------------------------- arrival times (--times)
def _write(path: Path, column: str, values) -> Path:
    path.write_text(f"{column}\n" + "".join(f"{v}\n" for v in values))
    return path


def _arrival_times(n: int = 60, seed: int = 11) -> list[str]:
    """Arrival times as a clock would log them: from 0, rounded to the millisecond."""
    return [f"{t:.3f}" for t in np.concatenate([[0.0], np.cumsum(thesis_draws(n, seed=seed))])]


def test_arrival_times_are_refused_without_times(tmp_path: Path):
    path = _write(tmp_path / "times.csv", "arrival_s", _arrival_times())
    out = tmp_path / "arrivals.yaml"
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(path), "--column", "arrival_s", "--out", str(out)))
    e = err.value
    assert e.file == str(path) and e.key == "arrival_s"
    assert e.value.startswith("61 values rising from 0.000 to ")  # not 'row 1 = 0: must be > 0'
    assert "--times" in e.why and "\n" not in str(e)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["times.csv"]


@pytest.mark.usefixtures("unlaid")  # its figure is not what it tests
def test_times_fits_the_differenced_column(tmp_path: Path, capsys):
    times = _write(tmp_path / "times.csv", "arrival_s", _arrival_times())
    gaps = np.diff(np.array(_arrival_times(), dtype=float))
    diffed = _write(tmp_path / "gaps.csv", "arrival_s", [repr(float(g)) for g in gaps])
    by_times, by_gaps = tmp_path / "a_times.yaml", tmp_path / "a_gaps.yaml"
    assert cmd_fit(parse(str(times), "--column", "arrival_s", "--times", "--out", str(by_times))) == 0
    assert cmd_fit(parse(str(diffed), "--column", "arrival_s", "--out", str(by_gaps))) == 0
    text = by_times.read_text()
    assert yaml.safe_load(text) == yaml.safe_load(by_gaps.read_text())
    assert "(60 gaps between 61 arrival times)" in text.splitlines()[0]
    assert "(60 values)" in by_gaps.read_text().splitlines()[0]
    capsys.readouterr()


def test_sorted_gaps_need_gaps_and_then_fit_as_unsorted(tmp_path: Path, capsys):
    x = thesis_draws(60, seed=5)
    ordinary = _write(tmp_path / "gaps.csv", "interarrival_s", [repr(float(v)) for v in x])
    in_order = _write(tmp_path / "sorted.csv", "interarrival_s", [repr(float(v)) for v in np.sort(x)])
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(in_order)))
    assert "--gaps" in err.value.why
    capsys.readouterr()
    assert cmd_fit(parse(str(ordinary))) == 0
    plain = yaml.safe_load(capsys.readouterr().out)
    assert cmd_fit(parse(str(ordinary), "--gaps")) == 0
    assert yaml.safe_load(capsys.readouterr().out) == plain
    assert cmd_fit(parse(str(in_order), "--gaps")) == 0
    sorted_fit = yaml.safe_load(capsys.readouterr().out)["arrivals"]
    assert sorted_fit["distribution"] == plain["arrivals"]["distribution"]
    assert sorted_fit["params"] == pytest.approx(plain["arrivals"]["params"], rel=1e-6)


def test_times_and_gaps_exclude_each_other():
    with pytest.raises(SystemExit):
        parse("t.csv", "--times", "--gaps")


def _times(values: list[str]) -> str:
    return "arrival_s\n" + "\n".join(values + _arrival_times(30)[1:]) + "\n"


BAD_TIMES = [
    ("goes back", _times(["0", "21.5", "20.0"]), "arrival_s[line 4]", "20.0", "not after 21.5 on line 3"),
    ("repeated", _times(["0", "21.5", "21.5"]), "arrival_s[line 4]", "21.5",
     "the same time as line 3: 1 of 32 gaps are 0"),
    ("not a number", _times(["0", "abc"]), "arrival_s[line 3]", "abc", "not a number"),
    ("infinite", _times(["0", "inf"]), "arrival_s[line 3]", "inf", "must be finite"),
    ("too few", "arrival_s\n" + "\n".join(_arrival_times(19)) + "\n", "arrival_s", "20 arrival times",
     "at least 21 arrival times"),
    ("evenly spaced", "arrival_s\n" + "\n".join(str(22 * i) for i in range(30)) + "\n", "arrival_s",
     "all 29 gaps = 22", "without variation"),
]


@pytest.mark.parametrize("label, text, key, value, why", BAD_TIMES, ids=[b[0] for b in BAD_TIMES])
def test_bad_arrival_times_are_refused(tmp_path: Path, label, text, key, value, why):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(path), "--column", "arrival_s", "--times", "--out", str(tmp_path / "a.yaml")))
    e = err.value
    assert (e.file, e.key, e.value) == (str(path), key, value)
    assert why in e.why
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.csv"]


def test_short_increasing_column_is_too_few_not_times(tmp_path: Path):
    """Below MIN_VALUES the order says little; the count is the problem."""
    path = _write(tmp_path / "short.csv", "interarrival_s", [f"{20 + i}" for i in range(10)])
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(path)))
    assert err.value.value == "10 values" and "at least 20 values" in err.value.why


def test_times_as_date_times_fit_as_their_seconds(tmp_path: Path, capsys):
    """--times takes ISO 8601 date-times (a log's arrival stamps, any one time zone) as
    their seconds: the same fit as the same instants written in seconds."""
    seconds = np.array(_arrival_times(), dtype=float)
    start = np.datetime64("2026-03-02T08:15:00", "ms")
    stamps = [str(start + np.timedelta64(int(round(t * 1000)), "ms")).replace("T", " ")
              for t in seconds]
    dated = _write(tmp_path / "dated.csv", "arrival_s", stamps)
    plain = _write(tmp_path / "plain.csv", "arrival_s", _arrival_times())
    assert cmd_fit(parse(str(dated), "--column", "arrival_s", "--times")) == 0
    by_dates = yaml.safe_load(capsys.readouterr().out)
    assert cmd_fit(parse(str(plain), "--column", "arrival_s", "--times")) == 0
    assert by_dates == yaml.safe_load(capsys.readouterr().out)
    bad = _write(tmp_path / "bad.csv", "arrival_s", [*stamps[:30], "soon", *stamps[31:]])
    with pytest.raises(ScenarioError) as err:
        cmd_fit(parse(str(bad), "--column", "arrival_s", "--times"))
    assert err.value.key == "arrival_s[line 32]" and err.value.value == "soon"
    assert "date-time" in err.value.why


# --------------------------------------------------------------------------- nested families
@pytest.mark.parametrize("n", [200, 10_000])
def test_threshold_fits_are_at_least_as_likely_as_the_exponential(n):
    """expon(loc, scale) is weibull_min(c=1, loc, scale) and gamma(a=1, loc, scale), so the
    three-parameter MLEs of those two can never be less likely than expon's MLE (loc = min(x)).
    Near-exponential data put the threshold within ~scale/n of min(x), where a fixed
    exclusion zone next to min(x) would cost them the ranking."""
    x = 17.6 + 5.4 * np.random.default_rng(3).weibull(1.02, n)
    fits = {f.family: f for f in fit_trace(x, families=("expon", "weibull_min", "gamma"))}
    x = subsample(x)  # more than MAX_FIT_VALUES are fitted on a subsample
    expon = stats.expon.logpdf(x, *stats.expon.fit(x)).sum()
    assert fits["expon"].loglik == pytest.approx(expon)
    for family in ("weibull_min", "gamma"):
        assert fits[family].loglik >= expon - 1e-6, family
