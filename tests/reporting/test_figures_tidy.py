"""The figures' small promises: shared axes where asked, Fig. 13 of a few draws, Fig. 13/14's
file names after the arrivals' family."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.patches import Rectangle

from cell.reporting.figures.interarrival import MIN_HISTOGRAM_DRAWS, distribution, draws, fig13_figure
from cell.reporting.figures.style import new_figure
from cell.scenario.schema import load_scenario
from tests.prose import in_order


def test_panels_share_the_x_axis_only_where_asked():
    fig, (top, bottom) = new_figure(23, "shared", nrows=2, sharex=True)
    bottom.set_xlim(3.0, 7.0)
    assert top.get_xlim() == (3.0, 7.0)
    fig.draw_without_rendering()
    assert not any(t.get_visible() and t.get_text() for t in top.get_xticklabels())
    assert any(t.get_text() for t in bottom.get_xticklabels())
    _, (left, right) = new_figure(23, "apart", nrows=2)
    right.set_xlim(3.0, 7.0)
    assert left.get_xlim() != (3.0, 7.0)


@pytest.mark.parametrize("n", [1, 3, 5, 8, 12])
def test_fig13_of_a_few_draws_keeps_the_pdf_readable(n: int):
    """A handful of draws is no spike towering over the pdf: the curve's peak stays at
    least 15 % of the panel's height (it was under 1 % for one draw)."""
    base = load_scenario("baseline")
    for seed in range(3):
        s = base.with_overrides({"run.seed": seed})
        ax = fig13_figure(s, draws(s, n)).axes[0]
        t = np.linspace(*ax.get_xlim(), 600)
        assert distribution(s).pdf(t).max() >= 0.15 * ax.get_ylim()[1]
        bars = [p for p in ax.patches if isinstance(p, Rectangle)]
        assert bool(bars) == (n >= MIN_HISTOGRAM_DRAWS)


def test_fig13_marks_too_few_draws_on_the_axis_and_says_so(tmp_path: Path):
    s = load_scenario("baseline")
    x = draws(s, 2)
    ax = fig13_figure(s, x).axes[0]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    (said,) = [text for text in texts if "too few" in text]
    assert in_order(said, f"the {len(x)} inter-arrival times", f"(seed {s.run.seed})", "too few",
                    "marked on the axis")
    (marks,) = [line for line in ax.get_lines() if line.get_marker() == "|"]
    assert sorted(marks.get_xdata()) == sorted(x)
    (tmp_path / "gaps.csv").write_text("interarrival_s\n18.5\n24\n")
    (tmp_path / "s.yaml").write_text("arrivals: {trace_csv: gaps.csv}\n")
    trace = load_scenario(tmp_path / "s.yaml")
    ax = fig13_figure(trace, draws(trace, 2)).axes[0]  # no pdf either: still a valid axis
    assert ax.get_ylim() == (0.0, 1.0)


@pytest.mark.parametrize(("arrivals", "pdf", "cdf"), [
    (None, "fig13_weibull_pdf", "fig14_weibull_cdf"),  # the thesis's
    ("{distribution: weibull_min, mean_s: 20, cv: 0.5}", "fig13_weibull_pdf", "fig14_weibull_cdf"),
    ("{distribution: gamma, mean_s: 20, cv: 0.5}", "fig13_gamma_pdf", "fig14_gamma_cdf"),
    ("{distribution: lognorm, mean_s: 20, cv: 0.3}", "fig13_lognormal_pdf", "fig14_lognormal_cdf"),
    ("{distribution: gengamma, params: {a: 2, c: 1.5, loc: 10, scale: 4}}", "fig13_gengamma_pdf",
     "fig14_gengamma_cdf"),
    ("{trace_csv: gaps.csv}", "fig13_trace_pdf", "fig14_trace_cdf")])
def test_fig13_14_files_are_named_after_the_arrivals(tmp_path: Path, arrivals: str | None,
                                                     pdf: str, cdf: str, unlaid):
    """Fig. 13/14 are written under the family's name, the thesis's for a Weibull, and a
    figure folder holding either is one `cell figures` may replace."""
    from cell.plumbing.output.atomic import OutputDir
    from cell.reporting.figures.thesis_figures import FILES, NAMES, make_figures

    (tmp_path / "gaps.csv").write_text("interarrival_s\n" + "\n".join(["18.5", "24", "21"] * 4))
    (tmp_path / "s.yaml").write_text(f"arrivals: {arrivals}\n" if arrivals else "name: s\n")
    s = load_scenario(tmp_path / "s.yaml")
    out = tmp_path / "figs"
    drawn = make_figures(s, out, parts=12, only=[12, 13, 14])
    assert [p.name for p in drawn] == [f"{FILES[12]}.png", f"{pdf}.png", f"{cdf}.png"]
    assert OutputDir.check(out, NAMES) == out.resolve()
