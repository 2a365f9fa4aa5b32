"""The report's precision table when the measure asked of is missing from the runs."""

from __future__ import annotations

import math
import re

import pytest

from cell.experiments.sweep import load_sweep, run_sweep
from cell.reporting.experiment.report import plan_report, write_report

# Figures drawn, neither laid out nor rasterised: these tests read the tables, markdown and CSVs.
pytestmark = pytest.mark.usefixtures("unlaid")


def gaps(scenario, seed) -> dict:
    """IP on even replications only, ip_thesis on none: measures some or all runs have no
    value of, as a run too short to deliver two parts has none."""
    import numpy as np

    r = int(seed.spawn_key[0])
    return {"ip_wallclock": math.nan if r % 2 else 1.0 + 0.01 * np.random.default_rng(seed).random(),
            "ip_thesis": math.nan, "parts_per_hr_wallclock": 100.0}


def precision_rows(sweeps, tmp_path, measure: str) -> list[list[str]]:
    path = sweeps.write(tmp_path, policies=["non-adaptive"], batch=3, replications={
        "precision": 1e-9, "measure": measure, "min": 3, "max": 9})
    sweep = load_sweep(path)
    frame = run_sweep(sweep, tmp_path / "o", workers=1, replicate=gaps,
                      progress=False).replications
    assert len(frame) == 9  # every round ran: the fact the table must state
    write_report(frame, sweep, plan_report(sweep, tmp_path / "rep"), "test")
    text = (tmp_path / "rep" / "report.md").read_text()
    table = text.split("## Precision", 1)[1].split("\n\n")[2].splitlines()
    return [[c.strip() for c in re.split(r"(?<!\\)\|", row)[1:-1]] for row in table[2:]]


def test_the_replications_column_counts_the_runs_not_the_values(sweeps, tmp_path):
    """9 runs, 5 with an IP (replications 0, 2, 4, 6, 8): 9 replications are said."""
    (row,) = precision_rows(sweeps, tmp_path, "ip_wallclock")
    assert row[1] == "9" and row[2].endswith(" %")


def test_a_measure_no_run_has_is_said_rather_than_inf(sweeps, tmp_path):
    (row,) = precision_rows(sweeps, tmp_path, "ip_thesis")
    assert row[1] == "9" and row[2] == "—" and "inf" not in " ".join(row)
    assert "0 of the runs gave ip_thesis a value" in row[3]
