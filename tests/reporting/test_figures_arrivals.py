"""Fig. 13 and 14 are titled after what they draw: the thesis's "Weibull pdf (cdf) of the
Inter-arrival Times" for its Weibull (eq. 6.9), the family's own name for any other
distribution, and a trace's data, with no family named, for a trace; the legend cites the
thesis's Weibull equations (6.8, 6.9) beside a Weibull's curves only."""

from __future__ import annotations

from pathlib import Path

import pytest
from matplotlib.figure import Figure

from cell.reporting.figures.interarrival import draws, fig13_figure, fig14_figure
from cell.scenario.schema import Scenario, load_scenario

FIGURES = {13: fig13_figure, 14: fig14_figure}
CURVE = {13: "pdf", 14: "cdf"}


def scenario_with(tmp_path: Path, arrivals: str) -> Scenario:
    """A scenario file with these arrivals (and a short trace beside it)."""
    (tmp_path / "gaps.csv").write_text("interarrival_s\n" + "\n".join(["18.5", "24", "21"] * 20))
    f = tmp_path / "s.yaml"
    f.write_text(f"arrivals: {arrivals}\n")
    return load_scenario(f)


def title(fig: Figure) -> str:
    suptitle = fig.get_suptitle()
    assert suptitle, "the figure has no title"
    return suptitle


@pytest.mark.parametrize("number", FIGURES)
def test_the_thesis_weibull_keeps_the_thesis_title(number: int) -> None:
    s = load_scenario("baseline")
    fig = FIGURES[number](s, draws(s, 200))
    assert title(fig) == f"Figure {number}. Weibull {CURVE[number]} of the Inter-arrival Times"


@pytest.mark.parametrize("number", FIGURES)
@pytest.mark.parametrize(("arrivals", "family"), [
    ("{distribution: gamma, mean_s: 20, cv: 0.5}", "Gamma"),
    ("{distribution: gamma, params: {a: 4, scale: 5}}", "Gamma"),
    ("{distribution: lognorm, mean_s: 20, cv: 0.3}", "Lognormal"),
    ("{distribution: expon, mean_s: 20, cv: 0.5}", "Exponential"),
    ("{distribution: weibull_min, mean_s: 20, cv: 0.5}", "Weibull"),
    ("{distribution: gengamma, params: {a: 2, c: 1.5, loc: 10, scale: 4}}", "gengamma")])
def test_a_distribution_is_named_in_the_title(tmp_path: Path, number: int, arrivals: str,
                                              family: str) -> None:
    s = scenario_with(tmp_path, arrivals)
    fig = FIGURES[number](s, draws(s, 200))
    assert title(fig) == f"Figure {number}. {family} {CURVE[number]} of the Inter-arrival Times"


@pytest.mark.parametrize("number", FIGURES)
def test_a_trace_is_titled_as_data(tmp_path: Path, number: int) -> None:
    s = scenario_with(tmp_path, "{trace_csv: gaps.csv}")
    text = title(FIGURES[number](s, draws(s, 60)))
    assert text.startswith(f"Figure {number}. ")
    assert text.endswith("of the Inter-arrival Times (trace)")
    assert not any(name in text for name in ("Weibull", "Gamma", "Lognormal", "Exponential",
                                             " pdf "))


def legend(fig: Figure) -> list[str]:
    (ax,) = [a for a in fig.axes if a.get_legend() is not None]
    return [t.get_text() for t in ax.get_legend().get_texts()]


@pytest.mark.parametrize("number", FIGURES)
def test_the_thesis_equations_are_cited_for_a_weibull_only(tmp_path: Path, number: int) -> None:
    """Eq. 6.8 is the Weibull pdf and eq. 6.9 its inverse cdf (docs/sources.md): the legend
    cites them beside a Weibull's curve, not beside a gamma's."""
    cited = {13: "pdf (eq. 6.8)", 14: "inverse cdf (eq. 6.9): "}[number]
    s = load_scenario("baseline")
    assert any(text.startswith(cited) for text in legend(FIGURES[number](s, draws(s, 200))))
    g = scenario_with(tmp_path, "{distribution: gamma, mean_s: 20, cv: 0.5}")
    texts = legend(FIGURES[number](g, draws(g, 200)))
    assert not any("eq. 6." in text for text in texts)
    assert any(text.startswith(cited.split(" (")[0]) for text in texts)  # the curve is there
