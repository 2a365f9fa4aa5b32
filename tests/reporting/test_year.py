"""The worked year (cell.reporting.year; reports/year/): the committed tables are what the
committed runs make, the report's headline and reading are generated from them, each run's
shifts add up to its year, and one short year's decomposition is the run's own summary."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cell.reporting import year

ROOT = Path(__file__).resolve().parents[2]
REPORT = ROOT / "reports" / "year"


@pytest.fixture(scope="module")
def committed() -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    return tuple(pd.read_csv(REPORT / f"{name}.csv") for name in ("runs", "shifts", "crews"))


def test_the_tables_are_the_runs_and_the_report_reads_them(committed):
    runs, shifts, crews = committed
    pd.testing.assert_frame_equal(year.shift_table(runs), shifts, check_dtype=False, rtol=1e-9)
    pd.testing.assert_frame_equal(year.crew_table(runs), crews, check_dtype=False, rtol=1e-9)
    text = (REPORT / "report.md").read_text(encoding="utf-8")
    assert year.headline(shifts, crews) in text
    for line in year.reading(shifts, crews):
        assert line in text


def test_each_runs_shifts_add_up_to_its_year_and_oee_and_losses_to_one(committed):
    """The shifts of the day tile the working time (two shifts, no time between them that is
    worked), so their planned hours and parts sum to the year's; every row's OEE and its five
    losses are the whole planned busy time."""
    runs, _, _ = committed
    for _, g in runs.groupby(["policy", "crew", "replication"]):
        whole = g[g["shift"] == "all"].iloc[0]
        parts = g[g["shift"] != "all"]
        assert parts["working_h"].sum() == pytest.approx(whole["working_h"])
        assert parts["parts_delivered"].sum() == whole["parts_delivered"]
        assert parts["parts_lost"].sum() == whole["parts_lost"]
    total = runs[["oee", "loss_downtime", "loss_starved", "loss_blocked", "loss_speed",
                  "loss_quality"]].sum(axis=1)
    np.testing.assert_allclose(total, 1.0, atol=1e-9)
    assert (runs.loc[runs["shift"] == "all", "working_h"] == 52 * 5 * 15.5).all()


def test_a_short_years_whole_row_is_the_runs_summary(tmp_path: Path):
    """A week of the year's scenario (its seed gives two robot failures and an output belt's,
    repaired by the first-shift crew only): the report's ``all`` row (its own
    decomposition of the robot's time) is the summary's OEE and losses, to rounding."""
    from cell.scenario.schema import load_scenario
    from cell.sim.simulation import simulate

    text = (ROOT / "scenarios" / "year.yaml").read_text().replace("weeks: 52", "weeks: 1")
    path = tmp_path / "year.yaml"
    path.write_text(text)
    rows = year.one_year(str(path), "non-adaptive", "first shift", 0)
    whole = next(r for r in rows if r["shift"] == "all")
    s = load_scenario(path, {"controller.policy": "non-adaptive",
                             "failures.repair.hours": [["06:00", "14:00"]]})
    summary = simulate(s, np.random.SeedSequence(s.run.seed, spawn_key=(0,)),
                       keep_parts=False, keep_belts=False).summary
    for m in year.MEASURES:
        assert whole[m] == pytest.approx(getattr(summary, m), abs=1e-9), m
    assert whole["parts_delivered"] == summary.parts_delivered
    assert whole["working_h"] == pytest.approx(summary.planned_time_s / 3600.0)
