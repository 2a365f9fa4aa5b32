"""docs/layout.md's worked example shows the stations.csv that ``cell run two_station_line``
writes today, byte for byte."""

from __future__ import annotations

import re
from pathlib import Path

from cell.cli.main import main

ROOT = Path(__file__).resolve().parents[2]


def test_the_worked_example_is_what_the_run_writes(tmp_path, capsys):
    text = (ROOT / "docs" / "layout.md").read_text(encoding="utf-8")
    shown = re.search(r"```csv\n(.*?)```", text, re.S).group(1)
    assert main(["run", "two_station_line", "--out", str(tmp_path / "line")]) == 0
    assert (tmp_path / "line" / "stations.csv").read_text(encoding="utf-8") == shown
