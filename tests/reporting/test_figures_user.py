"""``cell figures`` of a user's own scenario: Fig. 23/24 draw the non-adaptive robot that
``cell run`` runs and say at which cycle, Fig. 25-30 do not call a Table 7.1 cycle the
scenario's ideal; no figure says "nan" or lets a numpy warning out, however short the run;
an overloaded cell is said up front as ``cell run`` says it."""

from __future__ import annotations

import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure
from matplotlib.text import Text

from cell.cli.main import main
from cell.reporting.figures.runs import LOT, lot_means
from cell.reporting.figures.thesis_figures import FILES, make_figures
from cell.reporting.run_summary import warnings as run_warnings
from cell.scenario.schema import default_scenario, load_scenario
from cell.sim.assembly import assemble
from cell.sim.simulation import simulate
from tests.prose import in_order
from tests.reporting.conftest import unrendered_savefig

#: A user's fixed-cycle robot at its own 21 s, on arrivals of its own mean.
OWN_CYCLE = {"controller": {"policy": "non-adaptive", "ideal_cycle_s": 21.0,
                            "nominal_cycle_s": 22.0},
             "arrivals": {"distribution": "gamma", "mean_s": 22.0, "cv": 0.3}, "run.parts": 40}
#: Parts come faster than the robot's fastest cycle (docs/usage.md: overload).
OVERLOAD = "name: overload\narrivals: {distribution: weibull_min, mean_s: 16.0, cv: 0.05}\n"


def texts(s: Any, out: Path, only: list[int]) -> dict[int, str]:
    """Every visible text of each figure drawn, joined, by figure number; no warning may
    escape while they are drawn (laid out, not rasterised: the texts are what is asked)."""
    got: dict[int, str] = {}
    number = {stem: n for n, stem in FILES.items()}

    def savefig(fig: Figure, fname: Any, *args: Any, **kwargs: Any) -> None:
        stem = Path(fname).name.lstrip(".").split(".png")[0]
        got[number[stem]] = " | ".join(t.get_text().replace("\n", " ") for t in fig.findobj(Text)
                                       if t.get_visible() and t.get_text())
        unrendered_savefig(fig, fname, *args, **kwargs)

    with pytest.MonkeyPatch.context() as mp, warnings.catch_warnings():
        warnings.simplefilter("error")
        mp.setattr(Figure, "savefig", savefig)
        make_figures(s, out, only=only)
    return got


def test_fig23_24_draw_the_scenarios_own_fixed_cycle(tmp_path: Path):
    s = default_scenario().with_overrides(OWN_CYCLE)
    got = texts(s, tmp_path, [23, 24, 25])
    run = simulate(s)  # what `cell run` runs: the scenario's own non-adaptive robot at 21 s
    d, summary = run.parts, run.summary.as_dict()
    lumped = got[23]
    mean = float(np.nanmean(d["thesis_interval_s"]))
    assert in_order(lumped, "non-adaptive at 21.0000 s", f"mean {mean:.3f} s",
                    f"({100 * (mean / 21 - 1):+.1f} %", "against its cycle")
    assert "non-adaptive's cycle 21 s" in lumped and "ideal cycle 22 s" in lumped
    assert f"delivered: {summary['actual_cycle_thesis_s']:.3f} s" in lumped
    ideal = re.search(r"adaptive: mean [\d.]+ s \([+-][\d.]+ %", lumped)
    assert ideal and lumped[ideal.end():].startswith(" against the ideal")
    assert in_order(got[24], "non-adaptive at 21.0000 s", "after part 40")
    # Fig. 25 runs Table 7.1's 22.5872 s, which is not this scenario's ideal
    assert "IP-Ideal Cycle Time" not in got[25]
    assert in_order(got[25], "non-adaptive at Table 7.1's 22.5872 s", "adaptive at the ideal 22.0000 s")


def test_the_thesis_captions_stay_for_the_thesis_cell(tmp_path: Path):
    got = texts(load_scenario("baseline").with_overrides({"run.parts": 20}), tmp_path, [23, 26])
    assert in_order(got[26], "Figure 26. IP-Ideal Cycle Time", "22.0000 sec")
    assert "non-adaptive: mean " in got[23] and "against the ideal" in got[23]
    assert "non-adaptive at" not in got[23] and "non-adaptive's cycle" not in got[23]


@pytest.mark.parametrize(("parts", "numbers"), [
    (1, [13, 14, 22, 23, 24, 25]),  # one draw, one part: no time between two deliveries
    (5, [13, 14, 22, 23, 24, 25]),  # fewer parts than a lot: dots on the curves, one short lot
    (13, [23, 24]),  # a whole lot and a short one; Fig. 13, 14, 22, 25 draw 13 parts as they do 5
])
def test_a_short_run_says_no_nan_and_no_numpy_warning(tmp_path: Path, parts: int, numbers: list[int]):
    got = texts(default_scenario().with_overrides({"run.parts": parts}), tmp_path, numbers)
    for number, text in got.items():
        assert not re.search(r"\bnan\b", text, re.IGNORECASE), (number, text)
    short = parts % LOT
    if short:  # the last lot is drawn, and said to be short
        assert f"the last, hollow, holds only {short} part" in got[23]
    if parts == 1:
        assert "1 draw: " in got[13] and "sd" not in got[13].split("1 draw: ")[1]
        assert in_order(got[23], "no time between two deliveries", "in 1 part", "nothing")


def test_lots_keep_a_short_last_lot_and_a_lot_with_no_value():
    values = pd.Series([1.0, 3.0, *[np.nan] * (2 * LOT - 2), 5.0, 7.0, 9.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        x, y = lot_means(values)
    assert x.tolist() == [LOT, 2 * LOT, len(values)]
    assert y[0] == pytest.approx(2.0)  # the mean of the values it has
    assert np.isnan(y[1]) and y[2] == pytest.approx(7.0)  # a gap; the last lot of 3 parts


def test_no_part_delivered_says_so(tmp_path: Path):
    """The fixed robot of an overloaded cell delivers nothing in the thesis's bookkeeping."""
    scenario = tmp_path / "overload.yaml"
    scenario.write_text(OVERLOAD + "run: {parts: 30}\n")
    s = load_scenario(scenario)
    assert simulate(s.with_overrides({"controller.policy": "non-adaptive"})).parts[
        "missed_thesis"].all()
    note = texts(s, tmp_path / "figs", [23])[23]
    assert in_order(note, "no part delivered", "no actual cycle [2]")
    assert not re.search(r"\bnan\b", note)


def test_the_command_warns_of_an_overload_as_cell_run_does(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                          capsys: pytest.CaptureFixture[str], unlaid):
    import functools

    import cell.reporting.figures.thesis_figures
    # the figures of the runs only (Fig. 8-21 draw the path, which no warning is about)
    monkeypatch.setattr(cell.reporting.figures.thesis_figures, "make_figures",
                        functools.partial(make_figures, only=range(22, 31)))
    scenario = tmp_path / "overload.yaml"
    scenario.write_text(OVERLOAD + "run: {parts: 12}\n")
    assert main(["figures", "--scenario", str(scenario), "--out", str(tmp_path / "f")]) == 0
    err = capsys.readouterr().err
    expected = run_warnings(assemble(load_scenario(scenario)).k)
    assert expected and expected[0].startswith("offered load ")
    assert err.splitlines() == [f"cell: warning: {line}" for line in expected]
