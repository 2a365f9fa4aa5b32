"""The report's figures (cell.reporting.experiment.plots): which keys give panels and
which give a policy's own lines, one legend naming every line, titles that fit, and
intervals of counts that stop at 0."""

from __future__ import annotations

import matplotlib as mpl
import pytest

from cell.experiments.sweep import load_sweep, run_sweep
from cell.reporting.experiment.plots import (
    RC,
    TITLE_WIDTH,
    draw,
    figures,
    layout,
    title,
)
from cell.reporting.experiment.reading import show
from cell.reporting.experiment.report import summary_table
from cell.reporting.formatting import HEADLINES

PANEL_KEY = "belts.spacing_tol_in"


def counts(scenario, seed) -> dict:
    """Replication 0 loses 5 parts, the others none: a mean interval reaching below 0."""
    lost = 5 if seed.spawn_key[0] == 0 else 0
    return {"parts_missed": lost, "parts_per_hr_wallclock": 150.0 - lost
            + scenario.belts.input_nominal_in_s}


@pytest.fixture(scope="module")
def mixed(sweeps, tmp_path_factory):
    """Two keys every policy varies, and one key of its own per policy."""
    tmp = tmp_path_factory.mktemp("mixed")
    path = sweeps.write(tmp, grid={"belts.input_nominal_in_s": [2.5, 3.0],
                                   PANEL_KEY: [0.25, 0.5, 0.75]},
                        policies={"non-adaptive": {"controller.ideal_cycle_s": [22.0, 21.0]},
                                  "adaptive": {"belts.output_nominal_in_s": [1.8, 2.2]}})
    sweep = load_sweep(path)
    frame = run_sweep(sweep, tmp / "out", workers=1, replicate=counts, progress=False).replications
    return sweep, summary_table(frame, sweep), frame


def drawn(sweep, summary, column):
    h = next(h for h in HEADLINES if h.column == column)
    plan = layout(summary, sweep)
    panels = list(dict.fromkeys(tuple(show(v) for v in r)
                                for r in summary[list(plan.panels)].itertuples(index=False)))
    colours = {"non-adaptive": "red", "adaptive": "blue"}
    with mpl.rc_context(RC):
        return draw(h, summary[summary["measure"] == column], sweep, plan, panels, colours)


def test_panels_are_over_the_keys_every_policy_varies(mixed):
    sweep, summary, _ = mixed
    plan = layout(summary, sweep)
    assert plan.x == "belts.input_nominal_in_s"
    assert plan.panels == (PANEL_KEY,)
    assert plan.own == {"non-adaptive": ("controller.ideal_cycle_s",),
                        "adaptive": ("belts.output_nominal_in_s",)}


def test_every_panel_draws_both_policies_and_one_legend_names_every_line(mixed):
    sweep, summary, _ = mixed
    fig = drawn(sweep, summary, "parts_per_hr_wallclock")
    axes = [ax for ax in fig.axes if ax.get_visible()]
    assert len(axes) == 3  # one per value of the shared panel key, not per combination
    lines = ["non-adaptive: controller.ideal_cycle_s = 22",
             "non-adaptive: controller.ideal_cycle_s = 21",
             "adaptive: belts.output_nominal_in_s = 1.8",
             "adaptive: belts.output_nominal_in_s = 2.2"]
    for ax in axes:
        assert ax.get_legend_handles_labels()[1] == lines
        assert ax.get_legend() is None
    assert [t.get_text() for t in fig.legends[0].get_texts()] == lines
    assert [ax.get_title() for ax in axes] == [f"{PANEL_KEY} = {v}" for v in (0.25, 0.5, 0.75)]


def test_count_intervals_are_drawn_from_zero(mixed):
    sweep, summary, _ = mixed
    rows = summary[summary["measure"] == "parts_missed"]
    assert (rows["ci_low"] < 0).all()  # what the figure must not draw
    fig = drawn(sweep, summary, "parts_missed")
    lows = [path.vertices[:, 1].min() for ax in fig.axes for band in ax.collections
            for path in band.get_paths()]  # each line's band, a numeric x
    assert len(lows) == 3 * 4 and min(lows) == 0.0


def test_figures_are_the_same_bytes_twice(mixed):
    sweep, summary, frame = mixed
    first = figures(summary, frame, sweep)
    assert set(first) == {"fig_parts_missed.png", "fig_parts_per_hr_wallclock.png"}
    assert figures(summary, frame, sweep) == first


def test_a_title_breaks_between_pairs_to_fit_its_panel():
    pairs = [("arrivals.cv", "0.1"), ("controller.ideal_cycle_s", "22"),
             ("belts.output_nominal_in_s", "2.2"), ("arrivals.params.name", "thesis")]
    text = title(pairs)
    assert all(len(line) <= TITLE_WIDTH for line in text.splitlines())
    assert text.replace("\n", ", ") == ", ".join(f"{k.removesuffix('.name')} = {v}"
                                                 for k, v in pairs)
    assert title([("k" * 60, "1")]) == "k" * 60 + " = 1"  # too long alone: kept whole
    assert title([("a", "1"), ("b", "2")]) == "a = 1, b = 2"
