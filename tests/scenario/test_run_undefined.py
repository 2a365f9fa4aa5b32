"""``cell run`` when a figure has no value (one delivery has no delivery interval, so no
wall-clock cycle, rate or IP): printed as "—", left empty in summary.csv, never 'nan'."""

from __future__ import annotations

import csv
import math
import re
from pathlib import Path

from cell.cli.main import main
from cell.reporting.run_summary import UNDEFINED, format_summary, shown_figure
from cell.sim.records import RunSummary

NO_CYCLE = ("actual_cycle_wallclock_s", "parts_per_hr_wallclock", "ip_wallclock")


def test_a_run_of_one_delivery_prints_its_undefined_figures_as_dashes(tmp_path: Path, capsys):
    """A trace of 1e-9 s gaps: the run goes (exit 0) with the overload warned of, one part
    delivered; its wall-clock cycle, rate and IP are undefined in print and in the CSV alike."""
    (tmp_path / "trace.csv").write_text("interarrival_s\n" + "1e-9\n" * 30)
    (tmp_path / "s.yaml").write_text("arrivals:\n  trace_csv: trace.csv\nrun:\n  parts: 3\n")
    assert main(["run", str(tmp_path / "s.yaml"), "--out", str(tmp_path / "out"),
                 "--thesis"]) == 0
    shown = capsys.readouterr()
    assert "cell: warning: offered load" in shown.err
    assert not re.search(r"\bnan\b", shown.out, re.IGNORECASE), shown.out
    lines = dict(re.split(r"\s{2,}", line, maxsplit=1) for line in shown.out.splitlines()
                 if re.search(r"\s{2,}", line))
    assert lines["parts arrived / delivered"] == "3 / 1"
    for label in ("actual cycle, wall clock, s", "parts/hr, wall clock", "IP, wall clock"):
        assert lines[label] == "—", label
    assert lines["spacing min / max, in"] == "— / —"
    assert lines["actual cycle, thesis's accounting, s"] == "18.0841"  # defined: printed as ever
    with (tmp_path / "out" / "summary.csv").open(newline="") as fh:
        row = next(csv.DictReader(fh))
    assert [row[name] for name in NO_CYCLE] == ["", "", ""]
    assert row["parts_delivered"] == "1" and float(row["actual_cycle_thesis_s"]) > 0


def test_the_summary_table_prints_every_nan_figure_as_a_dash_and_the_rest_as_ever():
    s = RunSummary(policy="adaptive", actual_cycle_thesis_s=18.5, parts_delivered=1)
    assert math.isnan(s.actual_cycle_wallclock_s)
    table = format_summary(s)
    assert not re.search(r"\bnan\b", table, re.IGNORECASE), table
    assert re.search(r"actual cycle, wall clock, s\s+—$", table, re.MULTILINE)
    assert re.search(r"actual cycle, thesis's accounting, s\s+18\.5000$", table, re.MULTILINE)
    assert shown_figure(math.nan) == UNDEFINED and shown_figure(2.0, "{:.1f}") == "2.0"
