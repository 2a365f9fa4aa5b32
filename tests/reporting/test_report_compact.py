"""The compact report (issue 24): a 9-point two-policy sweep with a named baseline fits on
two screens and holds both comparisons; the Reading says where the parts go."""

from __future__ import annotations

from cell.experiments.sweep import load_sweep, run_sweep
from cell.reporting.experiment.report import difference_table, summary_table
from cell.reporting.experiment.text import markdown
from cell.reporting.formatting import HEADLINES
from tests.prose import in_order

#: Two screens of a terminal.
MAX_LINES = 120
GRID = {"belts.input_nominal_in_s": [2.5, 3.0, 3.5], "arrivals.mean_s": [20.0, 22.0, 24.0]}


def test_nine_points_two_policies_and_a_baseline_fit_two_screens(sweeps, tmp_path):
    path = sweeps.write(tmp_path, set={"run.parts": 20, "arrivals.distribution": "gamma",
                                       "arrivals.cv": 0.1, "controller.nominal_cycle_s": None},
                        grid=GRID, policies=["non-adaptive", "adaptive"], replications=3, batch=3,
                        baseline={"arrivals.mean_s": 22.0})
    sweep = load_sweep(path)
    frame = run_sweep(sweep, tmp_path / "o", workers=1, progress=False,
                      warn_windows=False).replications
    summary, differences = summary_table(frame, sweep), difference_table(frame, sweep)
    text = markdown(summary, differences, frame, sweep, "cell sweep", [])
    lines = text.splitlines()
    assert len(lines) <= MAX_LINES, len(lines)
    versus = set(differences["versus"])
    assert "non-adaptive" in versus  # the policies against each other ...
    assert any(v.startswith("adaptive at ") for v in versus)  # ... and against the baseline
    for h in HEADLINES:
        section = text.split(f"## {h.title}")[1].split("## ")[0]
        head = next(x for x in section.splitlines() if x.startswith("| "))
        assert "adaptive − non-adaptive" in head and "adaptive − baseline" in head
        assert "non-adaptive − baseline" in head and "| load |" in head
        rows = [x for x in section.splitlines() if x.startswith("| ") and x != head]
        assert len(rows) == 9  # a row per point: every comparison a column, not a bullet
    # the adaptive − non-adaptive cell of a row is differences.csv's paired mean there
    d = differences[(differences["measure"] == "parts_delivered")
                    & (differences["versus"] == "non-adaptive")]
    assert len(d) == 9
    reading = text.split("## Reading")[1]
    assert "What costs the parts, per point" in reading
    assert reading.count("(load ") == 9  # a line per point, with its load
    # the fixed-cycle robot's cycle follows each point's mean: said where a measure does not move
    ip = summary[(summary["measure"] == "ip_wallclock") & (summary["policy"] == "non-adaptive")]
    if ip["mean"].max() - ip["mean"].min() < 1e-9:
        assert in_order(reading, "its cycle follows", "mean inter-arrival time")
