"""Times to failure and repair given by their mean and spread (issue 33 item 4): ``mean_s`` or
``mean_h`` with ``shape`` or ``cv`` (cell/scenario/failure_spec.py, by the rule the arrivals'
``mean_s`` and ``cv`` use, cell/scenario/spread.py), beside scipy's ``params``."""

from __future__ import annotations

import contextlib
import io
import math
import re
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.cli.main import main
from cell.scenario.failure_sections import TimeDistribution
from cell.scenario.failure_spec import Draws, check_time, frozen, scipy_params

KEY = "failures.robot.time_to_failure"
#: Each family's scipy shape parameter, and the shapes tried.
SHAPES = {"weibull_min": ("c", st.floats(0.3, 20.0)), "gamma": ("a", st.floats(0.05, 100.0)),
          "lognorm": ("s", st.floats(0.05, 2.5))}
MEANS_S = st.floats(1.0, 1e7)
CVS = st.floats(0.05, 3.0)


def accepted(**given: object) -> TimeDistribution:
    """The time as a scenario holds it, after the checks a scenario's load makes."""
    spec = TimeDistribution(**given)  # type: ignore[arg-type]
    check_time(spec, KEY, "test.yaml")
    return spec


@settings(max_examples=40, deadline=None)
@given(family=st.sampled_from(sorted(SHAPES)), mean=MEANS_S, data=st.data())
def test_a_mean_and_a_shape_give_that_mean_and_that_shape(family: str, mean: float, data) -> None:
    name, shapes = SHAPES[family]
    shape = data.draw(shapes)
    dist = frozen(accepted(distribution=family, mean_s=mean, shape=shape))
    assert dist.kwds[name] == shape and dist.kwds.get("loc", 0.0) == 0.0
    assert float(dist.mean()) == pytest.approx(mean, rel=1e-9)


@settings(max_examples=40, deadline=None)
@given(family=st.sampled_from(sorted(SHAPES)), mean=MEANS_S, cv=CVS)
def test_a_mean_and_a_cv_give_that_mean_and_that_cv(family: str, mean: float, cv: float) -> None:
    dist = frozen(accepted(distribution=family, mean_s=mean, cv=cv))
    assert float(dist.mean()) == pytest.approx(mean, rel=1e-9)
    assert float(dist.std()) / float(dist.mean()) == pytest.approx(cv, rel=1e-7)


@settings(max_examples=20, deadline=None)
@given(mean_h=st.floats(1e-3, 1e4))
def test_an_exponential_by_its_mean_alone_and_hours_as_3600_seconds(mean_h: float) -> None:
    dist = frozen(accepted(distribution="expon", mean_h=mean_h))
    assert float(dist.mean()) == pytest.approx(mean_h * 3600.0, rel=1e-12)
    assert float(dist.std()) == pytest.approx(mean_h * 3600.0, rel=1e-12)
    assert float(dist.support()[0]) == 0.0
    for family in SHAPES:  # one shape: the unit is what is checked
        in_h = scipy_params(accepted(distribution=family, mean_h=mean_h, shape=1.5))
        in_s = scipy_params(accepted(distribution=family, mean_s=mean_h * 3600.0, shape=1.5))
        assert in_h == in_s


def test_a_weibull_of_mean_40_h_and_shape_1_5_is_its_scipy_form() -> None:
    """The issue's example: c = 1.5, scale = 40 h / Γ(1 + 1/1.5) (to the last bit or so: the
    resolution computes Γ as exp(ln Γ)); and the draws the simulation makes from it are those
    of the scipy form with the parameters it resolves to, bit for bit."""
    friendly = accepted(distribution="weibull_min", mean_h=40, shape=1.5)
    params = scipy_params(friendly)
    assert params["c"] == 1.5
    assert params["scale"] == pytest.approx(40 * 3600 / math.gamma(1 + 1 / 1.5), rel=1e-15)
    scipy_form = accepted(distribution="weibull_min", params=params)
    a, b = Draws(friendly, 7, 2100), Draws(scipy_form, 7, 2100)
    assert [a() for _ in range(600)] == [b() for _ in range(600)]


# --------------------------------------------------------------------------- cell run
def run(*argv: object) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def failures(ttf: str, ttr: str) -> str:
    return f"failures={{robot: {{time_to_failure: {ttf}, time_to_repair: {ttr}, clock: calendar}}}}"


#: Half an hour between failures, Weibull shape 1.5; repairs lognormal, 3 min, cv 0.8: by mean,
#: and as a user converts them by hand (scale = mean / Γ(1 + 1/c); σ = √ln(1 + cv²),
#: scale = mean / √(1 + cv²)).
BY_MEAN = failures("{distribution: weibull_min, mean_h: 0.5, shape: 1.5}",
                   "{distribution: lognorm, mean_s: 180, cv: 0.8}")
BY_HAND = failures(f"{{distribution: weibull_min, params: {{c: 1.5, scale: "
                   f"{1800 / math.gamma(1 + 1 / 1.5)!r}}}}}",
                   f"{{distribution: lognorm, params: {{s: {math.sqrt(math.log(1.64))!r}, "
                   f"scale: {180 / math.sqrt(1.64)!r}}}}}")


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, str]]:
    out = {}
    for name, value in (("by_mean", BY_MEAN), ("by_hand", BY_HAND)):
        folder = tmp_path_factory.mktemp(name) / "run"
        code, text, err = run("run", "baseline", "--set", "run.hours=3", "--set", value,
                              "--out", folder)
        assert code == 0, err
        out[name] = (folder, text)
    return out


def test_a_run_by_mean_draws_the_times_of_its_scipy_form(runs) -> None:
    (a, _), (b, _) = runs["by_mean"], runs["by_hand"]
    stops = (a / "failures.csv").read_bytes()
    assert stops.count(b"\n") > 3  # a few failures, so the draws are compared
    assert stops == (b / "failures.csv").read_bytes()
    assert (a / "summary.csv").read_bytes() == (b / "summary.csv").read_bytes()


def test_the_printed_mtbf_is_in_the_unit_written(runs) -> None:
    """``mean_h`` shows MTBF in hours; ``params`` (and ``mean_s``) in seconds; summary.csv
    keeps seconds either way (the test above: the two summaries are the same bytes)."""
    import pandas as pd

    folder, by_mean = runs["by_mean"]
    summary = pd.read_csv(folder / "summary.csv").iloc[0]
    mtbf = re.search(r"MTBF (\S+) (\w+), MTTR (\S+) (\w+)", by_mean)
    assert mtbf is not None and mtbf[2] == "h" and mtbf[4] == "s"
    assert float(mtbf[1]) == pytest.approx(summary.mtbf_observed_s / 3600, rel=1e-3)
    assert float(mtbf[3]) == pytest.approx(summary.mttr_observed_s, abs=0.05)
    hand = re.search(r"MTBF (\S+) (\w+), MTTR (\S+) (\w+)", runs["by_hand"][1])
    assert hand is not None and (hand[2], hand[4]) == ("s", "s")
    assert float(hand[1]) == pytest.approx(summary.mtbf_observed_s, abs=0.05)


# --------------------------------------------------------------------------- refusals
W = "distribution: weibull_min"
#: (id, the time to failure, the key named, the value named)
BAD = [
    ("mean_s and mean_h", f"{{{W}, mean_s: 3600, mean_h: 1, shape: 1.5}}", "mean_h", "1"),
    ("shape and cv", f"{{{W}, mean_h: 1, shape: 1.5, cv: 0.7}}", "cv", "0.7"),
    ("params and a mean", f"{{{W}, params: {{c: 1.5, scale: 3600}}, mean_h: 1, shape: 1.5}}",
     "params", "{'c': 1.5, 'scale': 3600.0}"),
    ("a shape without a mean", f"{{{W}, params: {{c: 1.5, scale: 3600}}, shape: 2.5}}", "shape",
     "2.5"),
    ("a Weibull by its mean alone", f"{{{W}, mean_h: 7}}", "mean_h", "7"),
    ("an exponential with a shape", "{distribution: expon, mean_h: 1, shape: 1.5}", "shape", "1.5"),
    ("an exponential with a cv", "{distribution: expon, mean_h: 1, cv: 0.5}", "cv", "0.5"),
    ("a family the mean cannot set", "{distribution: norm, mean_h: 1, cv: 0.1}", "distribution",
     "'norm'"),
    ("a Weibull cv beyond its solvable range", f"{{{W}, mean_h: 1, cv: 0.0001}}", "cv", "0.0001"),
    ("failures every microsecond (an event storm)", "{distribution: expon, mean_s: 0.000001}",
     "mean_s", "1e-06"),
]


@pytest.mark.parametrize("case", BAD, ids=[c[0] for c in BAD])
def test_a_time_given_half_or_twice_is_refused_in_one_line(tmp_path: Path, case) -> None:
    _, ttf, key, value = case
    scenario = tmp_path / "bad.yaml"
    scenario.write_text(f"run: {{hours: 1}}\n{failures(ttf, '{mean_s: 60}').replace('=', ': ', 1)}\n",
                        encoding="utf-8")
    out = tmp_path / "out"
    code, _, err = run("run", scenario, "--out", out)
    assert code == 2 and len(err.splitlines()) == 1, err
    assert str(scenario) in err and f"{KEY}.{key} = {value}" in err
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["bad.yaml"]

