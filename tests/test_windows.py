"""Counts over different windows: a sweep whose compared points differ in ``run.parts``
or ``run.warmup_parts`` warns once and leaves their counts out of ``differences.csv``,
as ``cell compare`` does (:mod:`cell.sweep.windows`)."""

from __future__ import annotations

from dataclasses import fields

import pandas as pd
import pytest

from cell.cli import main
from cell.records import RunSummary
from cell.reporting.headlines import HEADLINES
from cell.sweep.windows import count_measures

RATES = ("parts_per_hr_wallclock", "actual_cycle_wallclock_s", "ip_wallclock")


def sweep_run(sweeps, tmp_path, capsys, **fields) -> tuple[list[str], pd.DataFrame, str]:
    """``cell sweep --report`` over two replications: stderr's warning lines, differences.csv
    and report.md."""
    path = sweeps.write(tmp_path, replications=2, batch=2, **fields)
    code = main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--report", str(tmp_path / "rep")])
    err = capsys.readouterr().err
    assert code == 0, err
    return ([x for x in err.splitlines() if "warning" in x],
            pd.read_csv(tmp_path / "rep" / "differences.csv"),
            (tmp_path / "rep" / "report.md").read_text())


def test_the_counts_are_the_whole_number_measures_and_the_headlines_counts():
    ints = {f.name for f in fields(RunSummary) if f.type in (int, "int")}
    assert set(count_measures()) == ints - {"warmup_parts"}
    assert {h.column for h in HEADLINES if h.per_run} <= set(count_measures())
    assert not set(RATES) & set(count_measures())


def test_a_baseline_over_another_run_length_is_warned_and_its_counts_left_out(
        sweeps, tmp_path, capsys):
    warned, diffs, report = sweep_run(
        sweeps, tmp_path, capsys, policies=["non-adaptive"],
        grid={"run.parts": [20, 30]}, baseline={"run.parts": 20})
    assert len(warned) == 1, warned
    assert "1 of 1 paired comparisons" in warned[0] and "run.parts 30 against 20" in warned[0]
    assert "left out of differences.csv" in warned[0]
    assert not set(diffs["measure"]) & set(count_measures())
    assert set(RATES) <= set(diffs["measure"])
    said = warned[0].split("warning: ", 1)[1]
    assert f"**Caveat:** {said}." in report and report.index("**Caveat:**") < report.index("## ")


def test_only_the_pairs_over_different_warmups_lose_their_counts(sweeps, tmp_path, capsys):
    warned, diffs, _ = sweep_run(
        sweeps, tmp_path, capsys, policies=["non-adaptive", "adaptive"],
        grid={"run.warmup_parts": [0, 4]},
        baseline={"policy": "non-adaptive", "run.warmup_parts": 0})
    assert len(warned) == 1 and "2 of 3 paired comparisons" in warned[0]
    assert "run.warmup_parts 4 against 0" in warned[0] and "run.parts" not in warned[0]
    counted = diffs[diffs["measure"] == "parts_delivered"]
    assert list(zip(counted["policy"], counted["run.warmup_parts"])) == [("adaptive", 0)]
    rates = diffs[diffs["measure"] == "parts_per_hr_wallclock"]
    assert sorted(zip(rates["policy"], rates["run.warmup_parts"])) == [
        ("adaptive", 0), ("adaptive", 4), ("non-adaptive", 4)]


@pytest.mark.parametrize("baseline", [None, {"policy": "non-adaptive"}])
def test_pairs_over_the_same_window_are_not_warned(sweeps, tmp_path, capsys, baseline):
    """Each policy against the other at the same warm-up: the grid's windows differ, the
    pairs' do not."""
    warned, diffs, report = sweep_run(
        sweeps, tmp_path, capsys, policies=["non-adaptive", "adaptive"],
        grid={"run.warmup_parts": [0, 4]}, baseline=baseline)
    assert warned == [] and "Caveat" not in report
    counted = diffs[diffs["measure"] == "parts_delivered"]
    assert sorted(counted["run.warmup_parts"]) == [0, 4]


def test_the_warning_names_each_setting_with_its_values_on_either_side(sweeps, tmp_path):
    """Both window settings apart: each named once, its values in order of first appearance."""
    from cell.sweep import load_sweep
    from cell.sweep.windows import window_warning

    sweep = load_sweep(sweeps.write(
        tmp_path, policies=["non-adaptive"],
        grid={"run.parts": [20, 30, 40], "run.warmup_parts": [0, 4]},
        baseline={"run.parts": 20, "run.warmup_parts": 0}))
    assert window_warning(sweep) == (
        "5 of 5 paired comparisons are between points that count over different windows "
        "(run.parts 30, 40 against 20; run.warmup_parts 4 against 0): their counts "
        "(parts delivered, parts lost, spacings outside tolerance, ...) are not comparable "
        "and are left out of differences.csv; compare the rates, or give the points the "
        "same window")
