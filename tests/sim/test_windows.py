"""Counts and extremes over different windows: a sweep whose compared points differ in
``run.parts`` or ``run.warmup_parts`` warns once and leaves their counts and extremes out
of ``differences.csv``, as ``cell compare`` does (:mod:`cell.experiments.sweep.windows`)."""

from __future__ import annotations

from dataclasses import fields

import pandas as pd
import pytest

from cell.cli.main import main
from cell.experiments.sweep.windows import count_measures, extreme_measures, window_measures
from cell.reporting.formatting import HEADLINES
from cell.sim.records import RunSummary
from tests.prose import in_order

# Figures drawn, neither laid out nor rasterised: these tests read the tables, markdown and CSVs.
pytestmark = pytest.mark.usefixtures("unlaid")

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


def test_the_extremes_are_every_min_and_max_of_a_run_and_its_end():
    """Named, so that a new min/max column of RunSummary, or a column misread as one,
    shows here; and none of them a count or a rate."""
    assert set(extreme_measures()) == {
        "spacing_min_in", "spacing_max_in", "feed_delay_max_s", "input_speed_min_in_s",
        "input_speed_max_in_s", "output_speed_min_in_s", "output_speed_max_in_s", "sim_end_s"}
    floats = {f.name for f in fields(RunSummary) if f.type in (float, "float")}
    assert {m for m in floats if "_min_" in m or "_max_" in m} <= set(extreme_measures())
    assert set(window_measures()) == set(count_measures()) | set(extreme_measures())
    assert not set(RATES) & set(window_measures())


def test_a_baseline_over_another_run_length_is_warned_and_its_counts_left_out(
        sweeps, tmp_path, capsys):
    warned, diffs, report = sweep_run(
        sweeps, tmp_path, capsys, policies=["non-adaptive"], set=None,
        grid={"run.parts": [20, 30]}, baseline={"run.parts": 20})
    assert len(warned) == 1, warned
    assert "1 of 1 paired comparisons" in warned[0] and "run.parts 30 against 20" in warned[0]
    assert "counts and extremes" in warned[0] and "left out of differences.csv" in warned[0]
    assert not set(diffs["measure"]) & set(window_measures())
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
    for windowed in ("parts_delivered", "spacing_max_in"):
        kept = diffs[diffs["measure"] == windowed]
        # against the baseline only the point over its window; the policies compared at
        # warm-up 4 share theirs, so that pair keeps its counts too (issue 24)
        base = kept[kept["versus"] != "non-adaptive"]
        assert list(zip(base["policy"], base["run.warmup_parts"])) == [("adaptive", 0)]
        pair = kept[kept["versus"] == "non-adaptive"]
        assert list(zip(pair["policy"], pair["run.warmup_parts"])) == [("adaptive", 4)]
    rates = diffs[diffs["measure"] == "parts_per_hr_wallclock"]
    base = rates[rates["versus"] != "non-adaptive"]  # rates are compared whatever the window
    assert sorted(zip(base["policy"], base["run.warmup_parts"])) == [
        ("adaptive", 0), ("adaptive", 4), ("non-adaptive", 4)]
    assert len(rates) == len(base) + 1  # and the policies' pair at warm-up 4


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
    from cell.experiments.sweep import load_sweep
    from cell.experiments.sweep.windows import window_warning

    sweep = load_sweep(sweeps.write(
        tmp_path, policies=["non-adaptive"], set=None,
        grid={"run.parts": [20, 30, 40], "run.warmup_parts": [0, 4]},
        baseline={"run.parts": 20, "run.warmup_parts": 0}))
    said = window_warning(sweep)
    assert said.startswith(f"{3 * 2 - 1} of {3 * 2 - 1} paired comparisons ")  # all but the baseline
    assert in_order(said, "(run.parts 30, 40 against 20;", "run.warmup_parts 4 against 0)",
                    "left out of differences.csv", "the rates", "the same window")
    assert said.count("run.parts") == said.count("run.warmup_parts") == 1


def test_compare_over_different_run_lengths_leaves_out_the_extremes_and_keeps_the_rates(
        tmp_path, capsys):
    """Two scenario files, 30 and 45 parts: differences.csv has every measure of summary.csv
    but the counts and extremes, whose summaries it keeps; over one window, every one."""
    import yaml

    paths = []
    for name, parts in (("short", 30), ("long", 45)):
        paths.append(tmp_path / f"{name}.yaml")
        paths[-1].write_text(yaml.safe_dump({"run": {"parts": parts}}))

    def compare(out: str, *more: str) -> tuple[set[str], set[str]]:
        code = main(["compare", *map(str, paths), "--replications", "3", "--workers", "1",
                     "--out", str(tmp_path / out), *more])
        assert code == 0, capsys.readouterr().err
        capsys.readouterr()
        summarised, differenced = (set(pd.read_csv(tmp_path / out / f)["measure"])
                                   for f in ("summary.csv", "differences.csv"))
        return summarised, differenced

    summarised, differenced = compare("differ")
    extremes = {"spacing_min_in", "spacing_max_in", "input_speed_max_in_s",
                "output_speed_min_in_s", "feed_delay_max_s", "sim_end_s"}
    assert extremes <= summarised and not extremes & differenced
    assert differenced == summarised - set(window_measures())
    assert set(RATES) <= differenced
    summarised, differenced = compare("same", "--set", "run.parts=45")
    assert differenced == summarised and extremes | set(RATES) <= differenced
