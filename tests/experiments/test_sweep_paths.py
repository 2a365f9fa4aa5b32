"""A sweep over files (a trace, a dynamics model) names them as the sweep file wrote them
in replications.csv and the report, not by the absolute path they are read from."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest
import yaml

from cell.cli.main import main

# Figures drawn, neither laid out nor rasterised: these tests read the tables, markdown and CSVs.
pytestmark = pytest.mark.usefixtures("unlaid")


def _trace(path: Path, gap: float) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("interarrival_s\n" + f"{gap}\n" * 12)


def test_a_grid_of_trace_files_shows_their_names_as_written(tmp_path, monkeypatch, capsys):
    _trace(tmp_path / "a.csv", 24.0)
    _trace(tmp_path / "logs" / "b.csv", 26.0)
    sweep = tmp_path / "traces.yaml"
    sweep.write_text(yaml.safe_dump({
        "base": "baseline", "set": {"run.parts": 4},
        "grid": {"arrivals.trace_csv": ["a.csv", "logs/b.csv"]},
        "policies": ["adaptive"], "replications": 1}))
    monkeypatch.chdir(tmp_path)
    out, report = tmp_path / "out", tmp_path / "rep"
    code = main(["sweep", sweep.name, "--out", "out", "--report", "rep", "--workers", "1"])
    assert code == 0, capsys.readouterr().err
    with open(out / "replications.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["arrivals.trace_csv"] for r in rows] == ["a.csv", "logs/b.csv"]
    assert rows[0]["parts_arrived"] != "" and rows[0] != rows[1]  # two different runs
    text = (report / "report.md").read_text()
    assert "| logs/b.csv |" in text and str(tmp_path) not in text
