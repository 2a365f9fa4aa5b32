"""``cell run`` with failures: states.csv, failures.csv and a summary with OEE (issue 21)."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import pandas as pd
import pytest

from cell.cli.main import main

FAILURES = ("failures={robot: {time_to_failure: {distribution: expon, params: {scale: 7200}}, "
            "time_to_repair: {distribution: expon, params: {scale: 600}}, clock: calendar}}")


def run(*argv: str) -> tuple[int, str]:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        code = main(list(argv))
    return code, out.getvalue()


def test_an_eight_hour_run_with_robot_failures_writes_where_the_time_went(tmp_path: Path):
    out = tmp_path / "run"
    code, text = run("run", "baseline", "--set", "run.hours=8", "--set", FAILURES,
                     "--out", str(out))
    assert code == 0
    assert sorted(p.name for p in out.iterdir()) == [
        "belts.csv", "failures.csv", "parts.csv", "states.csv", "summary.csv"]
    summary = pd.read_csv(out / "summary.csv").iloc[0]
    assert summary.sim_end_s == 8 * 3600.0
    assert 0 < summary.availability < 1 and 0 < summary.loss_downtime < 1
    assert summary.oee == pytest.approx(summary.availability * summary.performance
                                        * summary.quality, rel=1e-8)  # CSV keeps ten digits
    losses = ["loss_downtime", "loss_starved", "loss_blocked", "loss_speed", "loss_quality"]
    assert summary.oee + summary[losses].sum() == pytest.approx(1.0, abs=1e-8)
    assert summary.parts_arrived == summary.parts_delivered + summary.parts_missed + \
        summary.parts_scrapped + summary.parts_in_cell
    stops = pd.read_csv(out / "failures.csv")
    assert list(stops.columns) == ["equipment", "cause", "from_s", "to_s", "part"]
    assert (stops.equipment == "robot").all() and (stops.cause == "failure").all()
    assert len(stops) == summary.robot_failures > 0
    states = pd.read_csv(out / "states.csv")
    assert list(states.columns) == ["equipment", "state", "from_s", "to_s"]
    robot = states[states.equipment == "robot"]
    # the robot's states tile the run: each begins where the last ended
    assert robot.from_s.iloc[0] == 0 and robot.to_s.iloc[-1] == 8 * 3600.0
    assert (robot.from_s.iloc[1:].to_numpy() == robot.to_s.iloc[:-1].to_numpy()).all()
    assert set(robot.state) <= {"busy", "waiting", "idle", "down", "maintenance"}
    down = robot[robot.state == "down"]
    assert (down.to_s - down.from_s).sum() / (8 * 3600.0) == \
        pytest.approx(summary.robot_down_fraction)
    assert "availability" in text and "loss_downtime" in text
    assert "robot busy (in motion)" in text


def test_without_failures_a_run_writes_its_three_files_and_the_busy_fraction(tmp_path: Path):
    out = tmp_path / "run"
    code, text = run("run", "baseline", "--set", "run.parts=30", "--out", str(out))
    assert code == 0
    assert sorted(p.name for p in out.iterdir()) == ["belts.csv", "parts.csv", "summary.csv"]
    summary = pd.read_csv(out / "summary.csv").iloc[0]
    assert summary.robot_down_fraction == 0 and summary.loss_downtime == 0
    assert f"robot busy (in motion) {summary.robot_busy_fraction:.3f}" in text
    loads = re.findall(r"offered load\b\D*([\d.]+)", text)
    assert loads == [f"{summary.offered_load:.3f}"] * 2  # the heading's and the busy line's: summary.csv's


def test_a_run_whose_motors_wear_writes_its_stops_and_counts_them(tmp_path: Path):
    """wear: on and no failures: section: the robot stops for worn motors, so the run writes
    failures.csv and states.csv, and the summary's downtime loss and MTBF count the stops."""
    out = tmp_path / "run"
    code, text = run("run", "baseline", "--set", "run.hours=3", "--set", "wear.enabled=true",
                     "--set", "wear.rated_life_h=0.5", "--set", "wear.repair_h=0.05",
                     "--out", str(out))
    assert code == 0
    assert sorted(p.name for p in out.iterdir()) == [
        "belts.csv", "failures.csv", "parts.csv", "states.csv", "summary.csv"]
    summary = pd.read_csv(out / "summary.csv").iloc[0]
    stops = pd.read_csv(out / "failures.csv")
    assert len(stops) == summary.robot_failures > 0
    assert (stops.equipment == "robot").all() and (stops.cause == "wear").all()
    down_s = (stops.to_s - stops.from_s).sum()
    assert summary.loss_downtime == pytest.approx(down_s / summary.sim_end_s)
    assert summary.loss_downtime > 0
    assert summary.mtbf_observed_s == pytest.approx(
        (summary.sim_end_s - down_s) / summary.robot_failures)
    states = pd.read_csv(out / "states.csv")
    down = states[(states.equipment == "robot") & (states.state == "down")]
    assert (down.to_s - down.from_s).sum() == pytest.approx(down_s)
    assert "availability" in text
