"""``cell compare A B``: two scenarios under common random numbers, paired."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path
from types import SimpleNamespace

import pandas as pd
import pytest
import scipy.stats
import yaml
from matplotlib.figure import Figure

from cell.cli.main import main
from cell.experiments.sweep import load_sweep, run_sweep
from cell.reporting.experiment.report import difference_table
from tests.prose import in_order

# Figures built, not laid out: these tests read the tables, markdown and CSVs.
pytestmark = pytest.mark.usefixtures("unlaid")


def scenario(tmp_path: Path, name: str, **settings) -> Path:
    doc = {"run": {"parts": 40}, "controller": {"policy": "adaptive"}}
    for key, value in settings.items():
        section, field = key.split("__")
        doc.setdefault(section, {})[field] = value
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def test_compare_agrees_with_the_sweeps_paired_differences(sweeps, tmp_path, capsys):
    a = scenario(tmp_path, "adaptive")
    b = scenario(tmp_path, "fixed", controller__policy="non-adaptive")
    code = main(["compare", str(a), str(b), "--replications", "6", "--seed", "11",
                 "--workers", "1", "--out", str(tmp_path / "cmp")])
    out, err = capsys.readouterr()
    assert code == 0, err
    ours = pd.read_csv(tmp_path / "cmp" / "differences.csv")

    sweep = load_sweep(sweeps.write(tmp_path, base=str(a), set={"run.parts": 40},
                                   policies=["non-adaptive", "adaptive"], replications=6,
                                   seed=11, batch=3))
    frame = run_sweep(sweep, tmp_path / "sweep", workers=1, progress=False).replications
    theirs = difference_table(frame, sweep)
    assert set(theirs["policy"]) == {"adaptive"} and set(theirs["versus"]) == {"non-adaptive"}
    merged = ours.merge(theirs, on="measure", suffixes=("", "_sweep"))
    assert len(merged) == len(theirs) > 20
    for col in ("n", "mean", "sd", "ci_low", "ci_high", "p_value"):
        pd.testing.assert_series_equal(merged[col], merged[col + "_sweep"], check_names=False,
                                       rtol=1e-9)
    # the verdict: A (adaptive) delivers more and loses fewer, the interval excluding zero
    delivered = ours[ours["measure"] == "parts_delivered"].iloc[0]
    assert delivered["ci_low"] > 0
    line = next(x for x in out.splitlines() if x.strip().startswith("Parts delivered"))
    half = (delivered["ci_high"] - delivered["ci_low"]) / 2
    assert "adaptive better" in line and "interval excludes 0" in line
    assert f"{delivered['mean']:.1f}" in line or f"{delivered['mean']:.2f}" in line
    assert f"{half:.1f}" in line or f"{half:.2f}" in line
    assert "6 replications of 40 parts, seed 11" in out.splitlines()[0]
    files = {p.name for p in (tmp_path / "cmp").iterdir()}
    assert {"report.md", "summary.csv", "differences.csv", "replications.csv"} <= files


def test_compare_paired_interval_is_scipys(tmp_path, capsys):
    a = scenario(tmp_path, "slow", belts__output_nominal_in_s=2.0)
    b = scenario(tmp_path, "fast", belts__output_nominal_in_s=2.5)
    assert main(["compare", str(a), str(b), "--replications", "5", "--workers", "1",
                 "--out", str(tmp_path / "cmp")]) == 0
    reps = pd.read_csv(tmp_path / "cmp" / "replications.csv")
    diffs = pd.read_csv(tmp_path / "cmp" / "differences.csv")
    x = reps[reps["scenario"] == "slow"].sort_values("replication")["spacing_max_in"]
    y = reps[reps["scenario"] == "fast"].sort_values("replication")["spacing_max_in"]
    row = diffs[diffs["measure"] == "spacing_max_in"].iloc[0]
    if (x.to_numpy() - y.to_numpy()).std() > 0:
        ci = scipy.stats.ttest_rel(x, y).confidence_interval(0.95)
        assert (row["ci_low"], row["ci_high"]) == pytest.approx((ci.low, ci.high), rel=1e-9)
    assert row["mean"] == pytest.approx((x.to_numpy() - y.to_numpy()).mean(), rel=1e-9)
    assert set(reps["seed"]) == {1984}  # A's run.seed


def test_compare_out_makes_each_table_once(tmp_path, capsys, monkeypatch):
    """The verdict and ``--out``'s files come from one summary and one difference table."""
    import cell.reporting.experiment.report as experiment

    made: list[str] = []
    for name in ("summary_table", "difference_table"):
        real = getattr(experiment, name)
        monkeypatch.setattr(experiment, name,
                            lambda *a, _real=real, _name=name: made.append(_name) or _real(*a))
    a = scenario(tmp_path, "one", run__parts=20)
    b = scenario(tmp_path, "two", run__parts=20, controller__policy="non-adaptive")
    compare_run(capsys, a, b, "--out", str(tmp_path / "cmp"))
    assert sorted(made) == ["difference_table", "summary_table"]
    assert {"summary.csv", "differences.csv"} <= {p.name for p in (tmp_path / "cmp").iterdir()}


def test_verdict_says_which_is_better_on_each_measure():
    from cell.experiments.sweep.spec import comparison
    from cell.reporting.compare_judgement import judgement, verdict
    from cell.scenario.schema import load_scenario

    a = load_scenario("baseline")
    sweep = comparison(a, a.with_overrides({"controller.policy": "non-adaptive"}),
                       ("a", "b"), 10, 1)
    summary = pd.DataFrame([
        {"scenario": s, "policy": p, "measure": m, "n": 10, "mean": v, "sd": 1.0,
         "ci_low": v - 1, "ci_high": v + 1, "run_p2_5": v - 2, "run_p97_5": v + 2}
        for s, p, vals in (("a", "adaptive", (500, 0, 1.01, 30.0)),
                           ("b", "non-adaptive", (400, 100, 0.80, 30.5)))
        for m, v in zip(("parts_delivered", "parts_missed", "ip_wallclock",
                         "actual_cycle_wallclock_s"), vals, strict=True)])
    diffs = pd.DataFrame([
        {"scenario": "a", "policy": "adaptive", "versus": "b", "measure": m, "n": 10,
         "mean": d, "sd": s, "ci_low": lo, "ci_high": hi, "p_value": 0.01}
        for m, d, s, lo, hi in (("parts_delivered", 100.0, 3.0, 98.0, 102.0),
                                ("parts_missed", -100.0, 3.0, -102.0, -98.0),
                                ("ip_wallclock", 0.21, 0.01, 0.20, 0.22),
                                ("actual_cycle_wallclock_s", -0.5, 2.0, -1.9, 0.9))])
    text = verdict(summary, diffs, sweep)
    lines = verdict_rows(text)
    _, judged = judgement(summary, diffs, sweep)
    # the paired means and the half-widths of their intervals, (ci_high - ci_low) / 2
    assert in_order(lines["Parts delivered"], "a better:", "delivers 100.0 ± 2.0 parts more",
                    "per 500-part run")
    assert in_order(lines["Parts lost (wall clock)"], "a better:", "loses 100.0 ± 2.0 parts fewer",
                    "per 500-part run")
    assert "a better (nearer 1 is better)" in lines["IP (wall clock, eq. 5.1)"] \
        and "means 1.01 against 0.8" in lines["IP (wall clock, eq. 5.1)"]
    assert "neither" in lines["Actual cycle (wall clock, s)"]
    assert "interval includes 0: no difference shown" in lines["Actual cycle (wall clock, s)"]
    assert "means 500 against 400" in lines["Parts delivered"]  # both sides' means, A first
    # overall: a ahead on three measures, neither on the fourth; the largest difference, 100
    # parts of 500 (200 per 1,000), decides
    assert [j.side for j in judged.judged] == [1, 1, 0, 1]
    assert (judged.winner, judged.deciding, judged.against, judged.trivial) == \
        ("a", "Parts delivered", (), ())
    assert judged.size("Parts delivered") == pytest.approx(200.0)
    assert judged.size("IP (wall clock, eq. 5.1)") == pytest.approx(190.0)  # 0.2 - 0.01 from 1
    assert text.splitlines()[-1].startswith("Overall")


@pytest.mark.parametrize(("args", "shows"), [
    (["nowhere.yaml", "baseline"], "nowhere.yaml"),
    (["baseline", "non_adaptive", "--replications", "1"], "--replications 1"),
    (["baseline", "non_adaptive", "--replications", "100000000000"],
     "--replications 100,000,000,000: at most 5,000,000"),  # years of runs, refused at once
    (["baseline", "non_adaptive", "--workers", "0"], "--workers 0"),
    (["baseline", "non_adaptive", "--seed", "-4"], "--seed -4"),
    (["baseline", "non_adaptive", "--set", "run.partz=3"], "run.partz"),
    (["baseline", "non_adaptive", "--set", "run.parts=-3"], "run.parts"),
])
def test_bad_compare_input_one_line_exit_2_nothing_written(tmp_path, capsys, args, shows):
    code = main(["compare", *args, "--out", str(tmp_path / "cmp")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and shows in err, err
    assert not (tmp_path / "cmp").exists()


def test_compare_refuses_an_out_that_is_a_file_before_running(tmp_path, capsys):
    blocker = tmp_path / "taken"
    blocker.write_text("x")
    code = main(["compare", "baseline", "non_adaptive", "--out", str(blocker)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "taken" in err
    assert blocker.read_text() == "x"


def compare_run(capsys, a: Path | str, b: Path | str, *more: str) -> tuple[str, list[str]]:
    """``cell compare A B`` over 3 replications: its stdout and its stderr's warning lines."""
    code = main(["compare", str(a), str(b), "--replications", "3", "--workers", "1", *more])
    out, err = capsys.readouterr()
    assert code == 0, err
    return out, [line for line in err.splitlines() if "warning" in line]


def verdict_rows(out: str) -> dict[str, str]:
    return {line.split("  ")[1].strip(): line for line in out.splitlines()[1:]
            if line.startswith("  ")}  # not the overall line (issue 24)


@pytest.fixture(scope="module")
def run_lengths(tmp_path_factory) -> SimpleNamespace:
    """``cell compare --out`` of runs of 30 and 45 parts (``differ``), and again with the
    ``--set run.parts=45`` its warning suggests (``same``): each one's stdout, warning lines and
    folder."""
    from tests.reporting.conftest import unlaid_savefig

    tmp = tmp_path_factory.mktemp("run_lengths")
    a = scenario(tmp, "short", run__parts=30)
    b = scenario(tmp, "long", run__parts=45, controller__policy="non-adaptive")
    said = {}
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Figure, "savefig", unlaid_savefig)
        for name, more in (("differ", []), ("same", ["--set", "run.parts=45"])):
            out, err = io.StringIO(), io.StringIO()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                code = main(["compare", str(a), str(b), "--replications", "3", "--workers", "1",
                             "--out", str(tmp / name), *more])
            assert code == 0, err.getvalue()
            said[name] = SimpleNamespace(
                out=out.getvalue(), folder=tmp / name,
                warned=[line for line in err.getvalue().splitlines() if "warning" in line])
    return SimpleNamespace(**said)


def test_compare_warns_once_when_run_lengths_differ_and_leaves_counts_uncompared(run_lengths):
    out, warned = run_lengths.differ.out, run_lengths.differ.warned
    assert len(warned) == 1, warned
    assert "short runs 30 parts, long 45" in warned[0] and "not comparable" in warned[0]
    assert "--set run.parts=45" in warned[0]
    rows = verdict_rows(out)
    for count in ("Parts delivered", "Parts lost (wall clock)", "Spacings outside 45 ± 0.25 in"):
        assert "not compared" in rows[count] and "run.parts 30 against 45" in rows[count]
        assert "better" not in rows[count]
    for rate in ("Parts per hour (wall clock)", "IP (wall clock, eq. 5.1)"):
        assert "not compared" not in rows[rate] and "±" in rows[rate]
    assert "3 replications of 30 and 45 parts" in out.splitlines()[0]
    # the suggested --set makes the windows equal: no warning, counts compared per run
    assert run_lengths.same.warned == []
    assert "per 45-part run" in verdict_rows(run_lengths.same.out)["Parts delivered"]


def test_compare_does_not_warn_when_windows_are_equal(tmp_path, capsys):
    a = scenario(tmp_path, "one", run__parts=30, run__warmup_parts=5)
    b = scenario(tmp_path, "other", run__parts=30, run__warmup_parts=5,
                 controller__policy="non-adaptive")
    out, warned = compare_run(capsys, a, b)
    assert warned == []
    assert "not compared" not in out
    assert "per 30-part run" in verdict_rows(out)["Parts lost (wall clock)"]


def test_compare_warns_when_warmups_differ(tmp_path, capsys):
    a = scenario(tmp_path, "auto", run__parts=30, run__warmup_parts="auto")
    b = scenario(tmp_path, "fixed", run__parts=30, run__warmup_parts=4)
    out, warned = compare_run(capsys, a, b)
    assert len(warned) == 1, warned
    assert "auto has run.warmup_parts auto, fixed 4" in warned[0]
    assert "--set run.warmup_parts=4" in warned[0] and "run.parts" not in warned[0]
    assert "not compared" in verdict_rows(out)["Parts delivered"]
    out, warned = compare_run(capsys, a, b, "--set", "run.warmup_parts=4")
    assert warned == [] and "not compared" not in out


def test_compare_report_carries_the_window_caveat(run_lengths):
    """``--out``'s report.md says what the warning said, before its tables; not otherwise."""
    report = (run_lengths.differ.folder / "report.md").read_text()
    said = run_lengths.differ.warned[0].split("warning: ", 1)[1]
    assert f"**Caveat:** {said}." in report
    assert report.index("**Caveat:**") < report.index("## ")
    assert "Caveat" not in (run_lengths.same.folder / "report.md").read_text()
    # differences.csv: the counts only over the same window, the rates either way
    differ, same = (set(pd.read_csv(run.folder / "differences.csv")["measure"])
                    for run in (run_lengths.differ, run_lengths.same))
    counts = {"parts_delivered", "parts_missed", "spacing_outside_tol"}
    assert counts <= same and not counts & differ
    assert "parts_per_hr_wallclock" in differ & same


def test_compare_warns_when_both_warmups_are_auto(tmp_path, capsys):
    """auto against auto: MSER-5 cuts each run apart, so counts are over different windows;
    the suggestion is a fixed warm-up (no number exists before the runs), and works."""
    a = scenario(tmp_path, "one", run__parts=30, run__warmup_parts="auto")
    b = scenario(tmp_path, "other", run__parts=30, run__warmup_parts="auto",
                 controller__policy="non-adaptive")
    out, warned = compare_run(capsys, a, b, "--out", str(tmp_path / "cmp"))
    assert len(warned) == 1, warned
    assert in_order(warned[0], "one has run.warmup_parts auto,", "other auto", "MSER-5",
                    "(--set run.warmup_parts=N,")
    rows = verdict_rows(out)
    assert "not compared" in rows["Parts delivered"] and "auto against auto" in rows[
        "Parts delivered"]
    assert "not compared" not in rows["Parts per hour (wall clock)"]
    measures = set(pd.read_csv(tmp_path / "cmp" / "differences.csv")["measure"])
    assert "parts_per_hr_wallclock" in measures and "parts_delivered" not in measures
    out, warned = compare_run(capsys, a, b, "--set", "run.warmup_parts=5")
    assert warned == [] and "not compared" not in out
