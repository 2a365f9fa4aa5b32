"""The committed reports are what today's code produces: Table 7.1's sweep run again into a
temporary folder gives reports/table_7_1/'s CSVs and markdown byte for byte, and the runs behind
the thesis's Fig. 22-30 (``cell figures``) give reports/figures_data.csv's numbers to the last bit.

A change to the model that moves a number must regenerate the report in the same commit:
``make sweep`` for Table 7.1, and for the figures' data ``CELL_REGENERATE=1 pytest
tests/reporting/test_reports_regenerate.py`` (beside ``make figures`` for the PNGs).
"""

from __future__ import annotations

import io
import os
from pathlib import Path

import pandas as pd
import pytest

from cell.cli.main import main
from cell.scenario import catalog

ROOT = Path(__file__).resolve().parents[2]
TABLE_7_1 = ROOT / "reports" / "table_7_1"
FIGURES_DATA = ROOT / "reports" / "figures_data.csv"
#: The files of Table 7.1's report that hold numbers and words (the PNGs are drawn from them).
TABLE_FILES = ("summary.csv", "differences.csv", "table_7_1.csv", "table_7_1.md", "report.md")
REGENERATE = os.environ.get("CELL_REGENERATE") == "1"


def test_table_7_1_is_what_the_code_gives(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                          unlaid: None) -> None:
    """``make sweep`` (200 replications x 7 rows x 500 parts) into a temporary folder; its
    figures are built, not laid out or drawn (the files compared are its numbers and words)."""
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.chdir(ROOT)  # the report names the sweep file as make sweep does
    report = tmp_path / "report"
    code = main(["sweep", "scenarios/table_7_1.yaml", "--out", str(tmp_path / "sweep"),
                 "--workers", "1", "--report", str(report)])
    assert code == 0
    for name in TABLE_FILES:
        assert (report / name).read_bytes() == (TABLE_7_1 / name).read_bytes(), \
            f"reports/table_7_1/{name} is not what the code gives: run make sweep and commit it"


def figures_data() -> str:
    """One row per run behind Fig. 22-30 (the adaptive run, the non-adaptive one at each of
    Table 7.1's cycles and at the scenario's own): its summary, every float to the last bit."""
    from cell.reporting.figures.runs import simulate_runs
    from cell.scenario.schema import load_scenario

    runs = simulate_runs(load_scenario(catalog.path("baseline")))
    rows = [{"run": "adaptive", **runs.adaptive.summary}]
    rows += [{"run": f"non-adaptive {cycle:.4f}", **run.summary}
             for cycle, run in sorted(runs.non_adaptive.items(), reverse=True)]
    out = io.StringIO()
    pd.DataFrame(rows).to_csv(out, index=False, float_format=lambda v: repr(float(v)), lineterminator="\n")
    return out.getvalue()


def test_the_figures_data_is_what_the_code_gives() -> None:
    text = figures_data()
    if REGENERATE:
        FIGURES_DATA.write_text(text)
    assert text == FIGURES_DATA.read_text(), \
        "reports/figures_data.csv is not what the code gives: regenerate it (see this module)"
