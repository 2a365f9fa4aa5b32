"""``cell run`` leads with the plant's measures (throughput, OEE and its losses by summary.csv's
names, parts lost); the thesis's accounting follows for a thesis scenario or with --thesis."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import pandas as pd

from cell.cli.main import main
from cell.sim.oee import LOSSES

THESIS_ROWS = ("IP, thesis's accounting", "Vavg R IV, in/s", "parts lost (thesis's accounting)")


def run(*argv: str) -> tuple[int, str]:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        code = main(list(argv))
    return code, out.getvalue()


def labels(text: str) -> list[str]:
    """The summary table's row labels, in order."""
    return [re.split(r"\s{2,}", line, maxsplit=1)[0] for line in text.splitlines()
            if re.search(r"\S\s{2,}\S", line)]


def test_a_thesis_scenario_prints_the_plants_measures_then_the_thesis_accounting(tmp_path: Path):
    out = tmp_path / "a"
    code, text = run("run", "non_adaptive", "--set", "run.parts=60", "--out", str(out))
    assert code == 0
    rows = labels(text)
    oee_row = rows.index("OEE (ISO 22400-2)")
    assert rows.index("parts/hr, wall clock") < oee_row
    assert all(rows.index(label) > oee_row for label in THESIS_ROWS)
    summary = pd.read_csv(out / "summary.csv").iloc[0]
    # the waterfall's steps are summary.csv's columns, each as its share
    said = dict(re.findall(r"(loss_\w+) (-?[\d.]+)%", text))
    assert list(said) == list(LOSSES)
    for name in LOSSES:
        assert said[name] == f"{100 * summary[name]:.1f}"
    # the fixed-cycle robot's OEE as a plant counts it: every part set down is good
    assert summary.quality == 1.0 and summary.oee > 0.5


def test_another_scenario_prints_the_thesis_accounting_only_when_asked(tmp_path: Path):
    base = ("run", "baseline", "--set", "name=mine", "--set", "run.parts=30")
    code, text = run(*base, "--out", str(tmp_path / "a"))
    assert code == 0 and "OEE (ISO 22400-2)" in labels(text)
    assert not set(THESIS_ROWS) & set(labels(text))
    code, text = run(*base, "--thesis", "--out", str(tmp_path / "b"))
    assert code == 0 and set(THESIS_ROWS) <= set(labels(text))
    # both runs' files hold the thesis's accounting alike
    a, b = (pd.read_csv(tmp_path / d / "summary.csv") for d in "ab")
    assert a.equals(b) and "ip_thesis" in a.columns
