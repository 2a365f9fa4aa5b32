"""Which fit ``cell fit`` writes, and the caution when it does not stand for the data: a fit
that moves the data's mean misleads every what-if built on it, so the table's ranking is
written only while its best keeps the mean and passes the KS test."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy import stats

from cell.cli.fit import add_arguments
from cell.cli.fit import main as cmd_fit
from cell.experiments.fit.choice import CAUTION_OFF, P_FLOOR, caution, choose
from cell.experiments.fit.mle import Fit, fit_trace
from cell.scenario.schema import load_scenario
from tests.prose import in_order

#: A line that runs at one pace, with bursts: 12 s gaps, every fifth 60 s (mean 21.6 s).
BURSTS = np.array([60.0 if i % 5 == 0 else 12.0 for i in range(1, 101)])


def parse(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    return parser.parse_args(list(argv))


def fit_of(family: str, p_value: float = 0.5, **params: float) -> Fit:
    """A fit with these parameters (its KS p-value as given; the rest unused here)."""
    return Fit(family, dict(params), 0.05, p_value, 0.0, 0.0)


def test_bursts_get_the_fit_that_keeps_the_mean_and_a_caution(tmp_path: Path, capsys):
    """The lognormal wins by AIC with mean 38.8 s; the gamma keeps 21.6 s and is written, and the
    warning and the YAML both say the fit does not stand for the data and how to replay them."""
    trace = tmp_path / "bursts.csv"
    trace.write_text("part,interarrival_s\n" + "".join(f"{i},{v}\n" for i, v in enumerate(BURSTS, 1)))
    (tmp_path / "what-if").mkdir()
    out = tmp_path / "what-if" / "arrivals.yaml"
    assert cmd_fit(parse(str(trace), "--out", str(out))) == 0
    printed = capsys.readouterr()
    assert printed.out.splitlines()[2].split()[1] == "lognorm"  # the ranking is AIC's, unchanged
    text = out.read_text()
    arrivals = yaml.safe_load(text)["arrivals"]
    assert arrivals["distribution"] == "gamma"
    gamma = stats.gamma(**arrivals["params"])
    assert gamma.mean() == pytest.approx(BURSTS.mean(), rel=1e-6)
    # the fit's mean and sd against the data's: the numbers the choice and the caution state
    fitted = (f"mean {gamma.mean():.3g} s", f"sd {gamma.std():.3g} s")
    data = (f"{BURSTS.mean():.3g} s", f"{BURSTS.std(ddof=1):.3g} s")
    (chosen,) = [line for line in printed.out.splitlines() if line.startswith("Chosen: ")]
    assert in_order(chosen, "Chosen: gamma", *fitted, *data, "lognorm", "mean 38.83 s")
    warning = printed.err.strip()
    assert warning.count("\n") == 0
    assert in_order(warning, "cell: warning: the fitted gamma", "does not stand", *fitted, *data,
                    "KS test rejects", f"{len(set(BURSTS))} distinct values",
                    "arrivals: {trace_csv: ../bursts.csv}")
    comments = " ".join(line[2:] for line in text.splitlines() if line.startswith("# "))
    assert "CAUTION: the fitted gamma" in comments
    assert warning.removeprefix("cell: warning: ") in comments
    # the suggested line, put in the written file's place, replays the data themselves
    out.write_text("arrivals: {trace_csv: ../bursts.csv}\n")
    assert load_scenario(out).arrivals.trace_csv is not None
    from cell.scenario.arrivals import mean_interarrival

    s = load_scenario(out)
    assert mean_interarrival(s.arrivals, s.base_dir) == pytest.approx(21.6)


def test_the_caution_names_what_is_off() -> None:
    x = stats.gamma(a=4.0, loc=10.0, scale=2.0).rvs(500, random_state=np.random.default_rng(2))
    right = {"a": 4.0, "loc": 10.0, "scale": 2.0}
    assert caution(fit_of("gamma", **right), x) == ""
    rejected = caution(fit_of("gamma", p_value=P_FLOOR / 2, **right), x)
    assert in_order(rejected, "the fitted gamma", "does not stand", "mean 18")
    assert rejected.endswith(f"rejects it (p = 0.0005 < {P_FLOOR:g})")
    shifted = caution(fit_of("gamma", **{**right, "loc": 12.0}), x)  # mean 20 s, the data's 18
    data = f"the data's {x.mean():.4g} s and {x.std(ddof=1):.4g} s"
    assert in_order(shifted, "the fitted gamma", "does not stand", "mean 20 s", "sd 4 s")
    assert shifted.endswith(data) and "KS" not in shifted
    wide = caution(fit_of("gamma", **{**right, "a": 9.0, "loc": 0.0}), x)  # mean 18 s, sd 6 s
    assert in_order(wide, "the fitted gamma", "does not stand", "mean 18 s", "sd 6 s")
    assert wide.endswith(data) and "KS" not in wide


def test_the_best_is_passed_over_only_when_it_misses_the_mean_or_sd() -> None:
    x = stats.gamma(a=4.0, loc=10.0, scale=2.0).rvs(500, random_state=np.random.default_rng(2))
    good = fit_of("gamma", a=4.0, loc=10.0, scale=2.0)
    near = fit_of("gamma", a=4.0, loc=10.0, scale=1.99)  # within the sampling error
    spread = fit_of("weibull_min", c=1.0, loc=10.0, scale=8.0)  # mean kept, sd 8 s (the data's 4)
    far = fit_of("expon", loc=10.0, scale=12.0)  # mean 22 s, sd 12 s
    normal = fit_of("norm", loc=18.0, scale=4.0)  # allows negative times
    assert choose([near, good], x) == (near, "")
    assert choose([fit_of("gamma", p_value=1e-9, a=4.0, loc=10.0, scale=2.0), good], x)[1] == ""
    chosen, why = choose([spread, far, good], x)
    assert chosen is good and why.startswith("Chosen: gamma (mean 18 s, sd 4 s)")
    assert why.endswith("the best, weibull_min, has sd 8 s.")
    assert choose([far, spread], x) == (spread, choose([far, spread], x)[1])  # the mean first
    assert choose([far, spread], x)[1].endswith("the best, expon, has mean 22 s.")
    chosen, why = choose([normal, good], x)
    assert chosen is good and in_order(why, "Chosen: gamma", "(norm allows negative times)")
    with pytest.raises(ValueError):
        choose([normal], x)


@pytest.mark.parametrize("dist, n", [
    (stats.weibull_min(c=1 / 0.2038, loc=17.6019, scale=5.4342), 400),
    (stats.lognorm(s=1.2, scale=10.0), 200),  # heavy-tailed: its sample sd rarely shows the tail
    (stats.expon(loc=15.0, scale=7.0), 50),
])
def test_samples_of_the_families_keep_the_ranking_and_are_not_said_to_misfit(dist, n) -> None:
    """The right family's fit is written; a caution, when its sd is more than 10 % off the
    sample's, says that is within the sample's own sampling error (a small or heavy-tailed
    sample's sd is often that far off its distribution's), not that the fit does not stand."""
    for seed in range(2):
        x = dist.rvs(n, random_state=np.random.default_rng(seed))
        fits = fit_trace(x)
        best = next(f for f in fits if f.nonnegative)
        assert choose(fits, x)[0] is best
        said = caution(best, x)
        assert said == "" or in_order(said, "within the sampling error", f"of {n} values")
        assert "does not stand" not in said, (seed, said)
        mean, sd, _ = best.fitted_moments()
        off = max(abs(sd / x.std(ddof=1) - 1.0), abs(mean / x.mean() - 1.0))
        assert (said != "") == (off > CAUTION_OFF)


def test_times_point_to_a_trace_of_gaps(tmp_path: Path, capsys):
    """Arrival times are no trace as they are: the pointer says what trace_csv takes."""
    path = tmp_path / "times.csv"
    path.write_text("arrival_s\n" + "".join(f"{t}\n" for t in np.concatenate([[0.0], np.cumsum(BURSTS)])))
    assert cmd_fit(parse(str(path), "--column", "arrival_s", "--times")) == 0
    printed = capsys.readouterr()
    assert set(yaml.safe_load(printed.out)) == {"arrivals"}  # the caution is a comment of the YAML
    err = printed.err
    assert in_order(err, "replay them: arrivals.trace_csv", "gaps", "interarrival_s")
