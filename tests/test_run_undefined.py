"""``cell run`` when a figure has no value (one delivery has no delivery interval, so no
wall-clock cycle, rate or IP): printed as "—", left empty in summary.csv, never 'nan'."""

from __future__ import annotations

import csv
import math
import re
from pathlib import Path

from cell.cli import main
from cell.commands.run import Undefined, printable
from cell.records import RunSummary

NO_CYCLE = ("actual_cycle_wallclock_s", "parts_per_hr_wallclock", "ip_wallclock")


def test_a_run_of_one_delivery_prints_its_undefined_figures_as_dashes(tmp_path: Path, capsys):
    """A trace of 1e-9 s gaps: the run goes (exit 0) with the overload warned of, one part
    delivered; its wall-clock cycle, rate and IP are undefined in print and in the CSV alike."""
    (tmp_path / "trace.csv").write_text("interarrival_s\n" + "1e-9\n" * 30)
    (tmp_path / "s.yaml").write_text("arrivals:\n  trace_csv: trace.csv\nrun:\n  parts: 3\n")
    assert main(["run", str(tmp_path / "s.yaml"), "--out", str(tmp_path / "out")]) == 0
    shown = capsys.readouterr()
    assert "cell: warning: utilisation" in shown.err
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


def test_printable_replaces_nan_only_and_leaves_the_summary_as_it_was():
    s = RunSummary(policy="adaptive", actual_cycle_thesis_s=18.5, parts_delivered=1)
    p = printable(s)
    assert math.isnan(s.actual_cycle_wallclock_s) and type(s.actual_cycle_wallclock_s) is float
    assert isinstance(p.actual_cycle_wallclock_s, Undefined) and math.isnan(p.actual_cycle_wallclock_s)
    assert f"{p.actual_cycle_wallclock_s:.4f}" == str(p.actual_cycle_wallclock_s) == "—"
    assert (p.actual_cycle_thesis_s, p.parts_delivered, p.policy) == (18.5, 1, "adaptive")
    assert type(p.actual_cycle_thesis_s) is float
