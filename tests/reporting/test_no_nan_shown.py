"""NaN and inf are never shown as results (issue 35, item 6): a figure with no value is ``n/a``
or left out, with its reason; an interval that cannot be had (one replication, an overflowed
spread) is said in words, the mean still shown."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cell.cli.main import main
from cell.reporting.experiment.text import cell
from cell.reporting.formatting import estimate, plus_minus
from cell.reporting.run_summary import format_summary, oee_line
from cell.sim.records import RunSummary

BASE = Path(__file__).resolve().parents[2] / "scenarios" / "baseline.yaml"


def no_number_words(text: str) -> bool:
    low = text.lower()
    return "nan" not in low.replace("no interval", "") and "inf" not in low.replace("info", "")


@pytest.mark.parametrize(("mean", "half", "keeps_mean"), [
    (12.5, math.nan, True),  # one replication
    (12.5, math.inf, True),  # the spread overflowed
    (math.nan, math.nan, False),  # no run gives it
    (math.inf, math.nan, False),
])
def test_an_estimate_without_a_number_says_why(mean, half, keeps_mean):
    for text in (estimate(mean, half), plus_minus(mean, half), plus_minus(mean, half, True)):
        assert no_number_words(text) and "±" not in text
        assert ("12.5" in text) is keeps_mean


def test_a_summary_cell_with_an_overflowed_spread_shows_no_inf():
    """Runs of about 1e308 s: their sd overflows to inf in the report's statistics."""
    row = {"n": 3, "mean": 1.5e308, "sd": math.inf, "ci_low": -math.inf, "ci_high": math.inf,
           "run_p2_5": 1e308, "run_p97_5": 1.7e308}
    text = cell(row)
    assert no_number_words(text) and "1.5e+308" in text


def failing_run(tmp_path: Path) -> Path:
    path = tmp_path / "fails.yaml"
    path.write_text("run: {parts: 1}\nfailures:\n  robot:\n"
                    "    time_to_failure: {distribution: expon, params: {scale: 1}}\n"
                    "    time_to_repair: {distribution: expon, params: {scale: 100000}}\n"
                    "    part_in_hand: scrap\n")
    return path


def test_a_one_part_run_whose_robot_fails_shows_no_nan(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["run", str(failing_run(tmp_path)), "--out", str(out)]) == 0
    said = capsys.readouterr().out
    summary = pd.read_csv(out / "summary.csv")
    assert summary["parts_delivered"].iloc[0] == 0 and np.isnan(summary["quality"].iloc[0])
    assert np.isnan(summary["oee"].iloc[0])  # in the CSV an empty cell
    assert "nan" not in said.lower()
    oee = next(line for line in said.splitlines() if line.startswith("OEE"))
    assert "quality n/a" in oee and "OEE n/a" in oee


def test_the_summary_waterfall_of_a_run_without_deliveries_shows_no_nan():
    r = RunSummary(policy="adaptive", availability=0.5, performance=0.0, quality=math.nan,
                   oee=math.nan)
    assert "nan" not in format_summary(r).lower() and "nan" not in oee_line(r).lower()
    assert "nan" not in format_summary(r, accounting=False).lower()


def test_an_optimisation_with_one_replication_reports_no_nan(tmp_path, unrendered):
    path = tmp_path / "one.yaml"
    path.write_text(f"base: {BASE}\nset: {{run.parts: 20, controller.policy: non-adaptive}}\n"
                    "vary:\n  controller.ideal_cycle_s: {low: 20.1, high: 22.5, step: 0.3}\n"
                    "objectives: [{measure: parts_missed, goal: minimize}]\n"
                    "trials: 2\nreplications: 1\nseed: 7\n")
    assert main(["optimize", str(path), "--out", str(tmp_path / "out")]) == 0
    report = (tmp_path / "out" / "report.md").read_text(encoding="utf-8")
    best = pd.read_csv(tmp_path / "out" / "trials.csv")
    assert np.isnan(best["parts_missed_ci95"]).all()  # one replication: no interval
    assert "nan" not in report.lower().replace("no interval", "")
    assert "fewer than two replications" in report


@pytest.mark.parametrize("tiny", [-0.0, -1e-6, -4e-4])
def test_a_loss_that_rounds_to_zero_has_no_minus_sign(tiny):
    from cell.reporting.run_summary import waterfall_line

    r = RunSummary(policy="adaptive", availability=1.0, performance=1.0, quality=1.0, oee=1.0,
                   planned_time_s=100.0, loss_downtime=0.0, loss_starved=0.0, loss_blocked=0.0,
                   loss_speed=tiny, loss_quality=0.0)
    assert "-0.0" not in waterfall_line(r)
