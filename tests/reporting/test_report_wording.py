"""report.md's wording: a mean from fewer runs than the point had says so, and the reading
names the difference furthest from zero (by size, not "largest" of negatives) and where."""

from __future__ import annotations

import pandas as pd

from cell.experiments.sweep import load_sweep, run_sweep
from cell.reporting.experiment.report import difference_table, summary_table
from cell.reporting.experiment.text import markdown
from cell.reporting.formatting import half_width, plus_minus


def report(sweeps, tmp_path, **fields) -> tuple[str, pd.DataFrame, pd.DataFrame]:
    sweep = load_sweep(sweeps.write(tmp_path, **fields))
    frame = run_sweep(sweep, tmp_path / "o", workers=1, progress=False,
                      warn_windows=False).replications
    summary, differences = summary_table(frame, sweep), difference_table(frame, sweep)
    return markdown(summary, differences, frame, sweep, "cell sweep", []), summary, differences


def test_a_mean_from_fewer_runs_says_how_many(sweeps, tmp_path):
    """Runs too short for a rate give none: the table says from how many of the point's."""
    text, summary, _ = report(sweeps, tmp_path, policies=["non-adaptive"], set={},
                              grid={"run.parts": [1, 2, 3]}, replications=3, batch=3)
    rate = summary[summary["measure"] == "parts_per_hr_wallclock"].set_index("run.parts")
    table = text.split("## Parts per hour (wall clock)")[1].split("## ")[0]
    partial = [(parts, int(n)) for parts, n in rate["n"].items() if 0 < n < 3]
    assert partial, rate["n"]  # runs of 1 or 2 parts really leave some without a rate
    for parts, n in partial:
        line = next(x for x in table.splitlines() if x.startswith(f"| {parts} |"))
        assert line.endswith(f"(from {n} of 3 runs) |"), line
    full = [parts for parts, n in rate["n"].items() if n == 3]
    for parts in full:
        line = next(x for x in table.splitlines() if x.startswith(f"| {parts} |"))
        assert "from" not in line


def test_the_reading_gives_the_largest_difference_and_where(sweeps, tmp_path):
    """The parts lost's comparison: its largest difference (by size) and its point; when the
    smallest's interval lies apart from it, that one too, as an interaction."""
    text, _, differences = report(sweeps, tmp_path, set={"run.parts": 40},
                                  grid={"belts.output_nominal_in_s": [1.8, 2.0, 2.2]},
                                  policies=["adaptive", "non-adaptive"], replications=4,
                                  batch=4)
    lost = differences[differences["measure"] == "parts_missed"]
    far, near = lost.loc[lost["mean"].abs().idxmax()], lost.loc[lost["mean"].abs().idxmin()]
    line = next(x for x in text.splitlines() if x.startswith("- **Parts lost (wall clock).**"))
    said = line.split(f"{far['policy']} − {far['versus']} ")[1]

    def shown(r) -> str:
        return plus_minus(float(r["mean"]), half_width(r), signed=True)

    key = "belts.output_nominal_in_s"
    apart = max(far["ci_low"], near["ci_low"]) > min(far["ci_high"], near["ci_high"])
    if apart:
        assert said.startswith(f"from {shown(near)} ({near[key]:g}) to {shown(far)} "
                               f"({far[key]:g})") and "an interaction" in said
    else:
        assert said.startswith(f"{shown(far)} at most ({far[key]:g}), the same within")
