"""A report over runs whose warm-up MSER-5 chooses (``run.warmup_parts: auto``) does not
call its counts "per N-part run": their window is the parts after each run's own cut."""

from __future__ import annotations

import pandas as pd

from cell.experiments.sweep import load_sweep, run_sweep
from cell.reporting.experiment.report import difference_table, summary_table
from cell.reporting.experiment.text import markdown
from tests.prose import in_order


def report(sweeps, tmp_path, **fields) -> tuple[str, pd.DataFrame]:
    sweep = load_sweep(sweeps.write(tmp_path, policies=["non-adaptive", "adaptive"],
                                    replications=2, batch=2, **fields))
    frame = run_sweep(sweep, tmp_path / "o", workers=1, progress=False,
                      warn_windows=False).replications
    summary, differences = summary_table(frame, sweep), difference_table(frame, sweep)
    return markdown(summary, differences, frame, sweep, "cell sweep", []), frame


def headings(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.startswith("## Parts") and "run" in line]


def test_all_auto_names_no_number_of_parts(sweeps, tmp_path):
    text, frame = report(sweeps, tmp_path, set={"run.parts": 40, "run.warmup_parts": "auto"},
                         grid={"belts.output_nominal_in_s": [1.8, 2.0]})
    assert frame["warmup_parts"].nunique() > 1  # the cuts really differ run by run
    assert "part run" not in text
    delivered, lost = headings(text)
    assert delivered.startswith("## Parts delivered, per run,") and lost.startswith("## Parts lost")
    assert all(in_order(h, "per run", "warm-up MSER-5 chose") for h in (delivered, lost))


def test_some_auto_says_where_mser5_chose(sweeps, tmp_path):
    text, _ = report(sweeps, tmp_path, set={"run.parts": 40},
                     grid={"run.warmup_parts": [4, "auto"]})
    assert "part run" not in text
    assert in_order(headings(text)[0], "## Parts delivered, per run,", "MSER-5", "where it is auto")


def test_fixed_warmup_keeps_the_run_length(sweeps, tmp_path):
    text, _ = report(sweeps, tmp_path, set={"run.parts": 40, "run.warmup_parts": 4},
                     grid={"belts.output_nominal_in_s": [1.8, 2.0]})
    delivered, lost = headings(text)
    assert delivered.startswith("## Parts delivered") and lost.startswith("## Parts lost")
    assert [h.split(", per ")[1] for h in (delivered, lost)] == ["40-part run"] * 2
    assert "after the warm-up" not in text and "MSER-5" not in text
