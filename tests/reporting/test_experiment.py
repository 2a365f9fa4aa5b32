"""Any sweep's report, replications to a precision, tidy output and the what-if.

The statistics in the report tables are checked against scipy.stats computed
here from the replications; the precision rule against an independent replay of
the stopping rule on the same streams; the what-if's parameters against the
thesis's eq. 6.9 through scipy.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import scipy.stats
import yaml

from cell.cli.main import main
from cell.experiments.sweep import load_sweep, run_sweep
from cell.reporting.experiment.report import (
    difference_table,
    plan_report,
    summary_table,
    write_report,
)
from cell.scenario import catalog
from tests.prose import in_order

# Figures built, not laid out, in the tests that make their own reports (they read the
# tables, markdown and file names); known_report, module-scoped and so set up before any
# function fixture, draws real PNGs.
pytestmark = pytest.mark.usefixtures("unlaid")

ROOT = Path(__file__).resolve().parents[2]
WHATIF = ROOT / "reports" / "whatif"


# --------------------------------------------------------------------------- stand-ins
def known(scenario, seed) -> dict:
    """Normal draws with a mean that depends on the policy and the output belt: the
    policies share the stream, so their difference has a known, small spread."""
    z = np.random.default_rng(seed).standard_normal(2)
    adaptive = scenario.controller.policy == "adaptive"
    base = 100.0 + 4.0 * scenario.belts.output_nominal_in_s
    return {"parts_delivered": base + 3.0 * z[0] + (10.0 + 0.5 * z[1] if adaptive else 0.0),
            "parts_per_hr_wallclock": base + 2.0 * z[0], "spacing_outside_tol": 7}


#: Spread of the precision measure at each ideal cycle (the point's own variance).
SIGMA = {22.0: 0.5, 21.5: 5.0, 21.0: 60.0}


def noisy(scenario, seed) -> dict:
    """parts_per_hr_wallclock = 100 + sigma z, sigma set by the point's ideal cycle."""
    c = scenario.controller
    sigma = SIGMA.get(c.ideal_cycle_s, 1.0) if c.ideal_cycle_s is not None else 1.0
    return {"parts_per_hr_wallclock": 100.0 + sigma * np.random.default_rng(seed).standard_normal(),
            "ideal_cycle_s": c.ideal_cycle_s or c.nominal_cycle_s}


def small_sweep(sweeps, tmp_path: Path, **fields) -> Path:
    doc = {"grid": {"belts.output_nominal_in_s": [2.0, 2.5]},
           "policies": ["non-adaptive", "adaptive"], "replications": 12, "seed": 5, "batch": 4}
    doc.update(fields)
    return sweeps.write(tmp_path, **doc)


# --------------------------------------------------------------------------- intervals against scipy
@pytest.fixture(scope="module")
def known_report(sweeps, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("known")
    sweep = load_sweep(small_sweep(sweeps, tmp))
    frame = run_sweep(sweep, tmp / "out", workers=1, replicate=known, progress=False).replications
    target = plan_report(sweep, tmp / "rep")
    write_report(frame, sweep, target, "test")
    return sweep, frame, tmp / "rep"


def test_summary_csv_intervals_are_scipys_t_intervals(known_report):
    sweep, frame, rep = known_report
    summary = pd.read_csv(rep / "summary.csv")
    assert list(summary.columns) == ["belts.output_nominal_in_s", "policy", "measure", "n",
                                     "mean", "sd", "ci_low", "ci_high", "run_p2_5", "run_p97_5"]
    assert len(summary) == 4 * 3  # 2 belts x 2 policies, 3 measures
    rows = summary[summary["measure"] == "parts_delivered"]
    for r in rows.to_dict("records"):
        x = frame[(frame["policy"] == r["policy"]) & (frame["belts.output_nominal_in_s"]
                                                        == r["belts.output_nominal_in_s"])]
        x = x["parts_delivered"].to_numpy(float)
        lo, hi = scipy.stats.t.interval(0.95, x.size - 1, loc=x.mean(), scale=scipy.stats.sem(x))
        assert r["n"] == x.size == 12
        assert (r["mean"], r["sd"]) == pytest.approx((x.mean(), x.std(ddof=1)), rel=1e-9)
        assert (r["ci_low"], r["ci_high"]) == pytest.approx((lo, hi), rel=1e-9)
        assert (r["run_p2_5"], r["run_p97_5"]) == pytest.approx(np.percentile(x, [2.5, 97.5]))
    constant = summary[summary["measure"] == "spacing_outside_tol"]
    assert (constant["ci_low"] == 7).all() and (constant["sd"] == 0).all()


def test_differences_csv_is_scipys_paired_t(known_report):
    sweep, frame, rep = known_report
    diffs = pd.read_csv(rep / "differences.csv")
    assert list(diffs.columns) == ["belts.output_nominal_in_s", "policy", "versus", "measure", "n",
                                   "mean", "sd", "ci_low", "ci_high", "p_value"]
    d = diffs[diffs["measure"] == "parts_delivered"]
    assert len(d) == 2 and set(d["policy"]) == {"adaptive"} and set(d["versus"]) == {"non-adaptive"}
    for r in d.to_dict("records"):
        at = frame[frame["belts.output_nominal_in_s"] == r["belts.output_nominal_in_s"]]
        a = at[at["policy"] == "adaptive"].sort_values("replication")["parts_delivered"]
        b = at[at["policy"] == "non-adaptive"].sort_values("replication")["parts_delivered"]
        res = scipy.stats.ttest_rel(a.to_numpy(float), b.to_numpy(float))
        ci = res.confidence_interval(0.95)
        # common random numbers: the shared 3 z0 cancels, leaving 10 + 0.5 z1
        assert r["mean"] == pytest.approx(10.0, abs=0.5) and r["sd"] < 1.0
        assert (r["ci_low"], r["ci_high"]) == pytest.approx((ci.low, ci.high), rel=1e-9, abs=1e-9)
        assert r["p_value"] == pytest.approx(res.pvalue, rel=1e-6)


def test_report_md_prints_the_tables_intervals(known_report):
    sweep, frame, rep = known_report
    text = (rep / "report.md").read_text()
    summary = pd.read_csv(rep / "summary.csv")
    r = summary[(summary["measure"] == "parts_per_hr_wallclock") & (summary["policy"] == "adaptive")
                & (summary["belts.output_nominal_in_s"] == 2.5)].iloc[0]
    half = (r["ci_high"] - r["ci_low"]) / 2
    d = 1 - math.floor(math.log10(half))
    assert f"{r['mean']:.{d}f} ± {half:.{d}f}" in text
    diffs = pd.read_csv(rep / "differences.csv")
    q = diffs[(diffs["measure"] == "parts_delivered")].iloc[0]
    half = (q["ci_high"] - q["ci_low"]) / 2
    d = 1 - math.floor(math.log10(half))
    # the paired difference is the last column of its point's row in the measure's table
    table = text.split("## Parts delivered")[1].split("\n## ")[0]
    assert columns(table) == ["belts.output_nominal_in_s", "non-adaptive", "adaptive",
                              "adaptive − non-adaptive"]
    row = next(line for line in table.splitlines()
               if line.startswith(f"| {q['belts.output_nominal_in_s']:g} |"))
    assert row.endswith(f"| {q['mean']:+.{d}f} ± {half:.{d}f} |")
    # no variation is said, not shown as a zero-width interval
    assert "7 (no variation)" in text and "7.0 ± 0.0" not in text
    for name in ("fig_parts_delivered.png", "fig_parts_per_hr_wallclock.png",
                 "fig_spacing_outside_tol.png"):
        assert (rep / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and name in text
        assert (rep / name).stat().st_size > 1000  # drawn (not the unrendered stub)


# --------------------------------------------------------------------------- replications to a precision
def precision_sweep(sweeps, tmp_path: Path, **fields) -> Path:
    doc = {"policies": {"non-adaptive": {"controller.ideal_cycle_s": [22.0, 21.5, 21.0]}},
           "replications": {"precision": 0.01, "measure": "parts_per_hr_wallclock",
                            "min": 10, "max": 200},
           "seed": 3, "batch": 10}
    doc.update(fields)
    return sweeps.write(tmp_path, **doc)


def expected_stop(seed: int, sigma: float, precision: float, lo: int, hi: int, batch: int) -> int:
    """The stopping rule replayed with scipy on the same streams: after each whole round,
    stop once the t half-width is within precision x |mean|."""
    x = np.array([100.0 + sigma * np.random.default_rng(
        np.random.SeedSequence(seed, spawn_key=(r,))).standard_normal() for r in range(hi)])
    n = lo
    while True:
        half = scipy.stats.t.ppf(0.975, n - 1) * x[:n].std(ddof=1) / math.sqrt(n)
        if half <= precision * abs(x[:n].mean()) or n >= hi:
            return n
        n = min(n + batch, hi)


def test_precision_stops_where_the_rule_says_and_not_before(sweeps, tmp_path):
    sweep = load_sweep(precision_sweep(sweeps, tmp_path))
    outcome = run_sweep(sweep, tmp_path / "o", workers=1, replicate=noisy, progress=False)
    counts = [outcome.counts[i] for i in range(3)]
    assert counts == [expected_stop(3, SIGMA[c], 0.01, 10, 200, 10) for c in (22.0, 21.5, 21.0)]
    assert counts[0] == 10 and 10 < counts[1] < 200 and counts[2] == 200  # min, between, max
    frame = outcome.replications
    assert list(frame.groupby("point", sort=True).size()) == counts
    assert list(frame[frame["point"] == 1]["replication"]) == list(range(counts[1]))


def test_precision_same_bytes_with_1_and_2_workers_and_after_resume(sweeps, tmp_path):
    sweep = load_sweep(precision_sweep(sweeps, tmp_path))
    run_sweep(sweep, tmp_path / "w1", workers=1, replicate=noisy, progress=False)
    run_sweep(sweep, tmp_path / "w2", workers=2, replicate=noisy, progress=False)
    one = (tmp_path / "w1" / "replications.csv").read_bytes()
    assert one == (tmp_path / "w2" / "replications.csv").read_bytes()
    with pytest.raises(KeyboardInterrupt):  # killed in the middle of the rounds
        run_sweep(sweep, tmp_path / "cut", workers=1, replicate=sweeps.Interrupt(after=95, of=noisy),
                  progress=False)
    outcome = run_sweep(sweep, tmp_path / "cut", workers=1, resume=True, replicate=noisy,
                        progress=False)
    assert outcome.tasks_reused == 9
    assert (tmp_path / "cut" / "replications.csv").read_bytes() == one


def test_precision_report_says_per_point_whether_it_was_reached(sweeps, tmp_path):
    sweep = load_sweep(precision_sweep(sweeps, tmp_path))
    frame = run_sweep(sweep, tmp_path / "o", workers=1, replicate=noisy,
                      progress=False).replications
    write_report(frame, sweep, plan_report(sweep, tmp_path / "rep"), "test")
    text = (tmp_path / "rep" / "report.md").read_text()
    assert "## Precision" in text
    assert "not reached: stopped at max = 200" in text
    runs = frame.groupby("controller.ideal_cycle_s")["replication"].nunique()
    reached = int((runs < 200).sum())
    assert 0 < reached < len(runs)
    assert in_order(text, f"{reached} of {len(runs)} points reached",
                    f"{len(runs) - reached} stopped at the maximum of 200")
    # every row of every markdown table has as many cells as its header (a | in a cell,
    # as in "half-width / |mean|", is escaped, not a cell boundary)
    for table in re.findall(r"(?:^\|.*\|\n)+", text, flags=re.M):
        rows = table.splitlines()
        widths = {len(re.split(r"(?<!\\)\|", row)) for row in rows}
        assert len(widths) == 1, rows
    assert "half-width / \\|mean\\|" in text


def test_a_fixed_count_draws_the_same_streams_whatever_the_count(sweeps, tmp_path):
    few = load_sweep(sweeps.write(tmp_path, replications=3))
    many = load_sweep(sweeps.write(tmp_path, replications=3 * 10**6))    # the most allowed
    for r in (0, 2):
        assert (few.stream(r).generate_state(4) == many.stream(r).generate_state(4)).all()
        assert (many.stream(r).generate_state(4)
                == np.random.SeedSequence(7).spawn(3)[r].generate_state(4)).all()
    assert next(many.iter_tasks()).last == 2  # tasks are made one at a time


# --------------------------------------------------------------------------- tidy replications.csv
def test_replications_csv_is_tidy(sweeps, tmp_path):
    path = sweeps.write(tmp_path, grid={"arrivals.params": {
        "thesis": {"c": 4.906771344455348, "loc": 17.6019, "scale": 5.4342},
        "late": {"c": 4.906771344455348, "loc": 18.0, "scale": 5.4342}}},
        policies={"non-adaptive": {"controller.ideal_cycle_s": [22.0]}, "adaptive": {}},
        replications=2, batch=2)
    sweep = load_sweep(path)
    frame = run_sweep(sweep, tmp_path / "o", workers=1, replicate=sweeps.bookkeeping,
                      progress=False).replications
    assert list(frame.columns[:9]) == [
        "policy", "point", "arrivals.params.name", "arrivals.params.c", "arrivals.params.loc",
        "arrivals.params.scale", "controller.ideal_cycle_s", "seed", "replication"]
    assert frame["arrivals.params.loc"].dtype == float
    assert set(frame["arrivals.params.name"]) == {"thesis", "late"}
    # every row's cycle filled: the adaptive one runs at the nominal cycle
    assert not frame["controller.ideal_cycle_s"].isna().any()
    assert (frame["controller.ideal_cycle_s"] == frame["ideal_cycle_s"]).all()
    assert set(frame.loc[frame["policy"] == "adaptive", "controller.ideal_cycle_s"]) == {22.5872}
    assert frame["seed"].dtype == np.int64 and set(frame["seed"]) == {7}
    text = (tmp_path / "o" / "replications.csv").read_text()
    assert "{" not in text and "'" not in text  # no Python reprs
    # the seed columns reproduce the row's stream
    for row in frame.head(3).to_dict("records"):
        stream = np.random.SeedSequence(row["seed"], spawn_key=(row["replication"],))
        assert row["first_u"] == pytest.approx(np.random.default_rng(stream).random(), rel=1e-9)


def test_a_trace_driven_sweep_says_no_variation(sweeps, tmp_path):
    trace = tmp_path / "trace.csv"
    trace.write_text("interarrival_s\n" + "\n".join(["22.1", "23.0", "21.7", "22.9"] * 5) + "\n")
    path = sweeps.write(tmp_path, set={"run.parts": 20, "arrivals.trace_csv": str(trace)},
                       policies=["non-adaptive", "adaptive"], replications=3, batch=3)
    code = main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--report", str(tmp_path / "rep")])
    assert code == 0
    text = (tmp_path / "rep" / "report.md").read_text()
    assert "No variation between replications" in text and "trace" in text
    assert not [line for line in text.splitlines() if line.startswith("|") and " ± " in line]
    assert "(no variation)" in text
    # the difference, the same in every replication, is shown exact, without an interval
    reps = pd.read_csv(tmp_path / "o" / "replications.csv")
    diff = (reps[reps["policy"] == "adaptive"]["parts_delivered"].to_numpy()
            - reps[reps["policy"] == "non-adaptive"]["parts_delivered"].to_numpy())
    assert len(diff) == 3 and len(set(diff)) == 1 and diff[0] != 0
    table = text.split("## Parts delivered")[1].split("\n## ")[0]
    assert table.rstrip().endswith(f"| {diff[0]:+d} (exact) |")


# --------------------------------------------------------------------------- a small real sweep
def test_general_report_on_a_small_real_sweep(sweeps, tmp_path, capsys):
    path = small_sweep(sweeps, tmp_path, set={"run.parts": 30}, replications=3, batch=3)
    code = main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1",
                 "--report", str(tmp_path / "rep")])
    assert code == 0, capsys.readouterr().err
    frame = pd.read_csv(tmp_path / "o" / "replications.csv")
    summary = pd.read_csv(tmp_path / "rep" / "summary.csv")
    numeric = [c for c in frame.columns[frame.columns.get_loc("replication") + 1:]
               if pd.api.types.is_numeric_dtype(frame[c])]
    assert "parts_delivered" in numeric and "spacing_outside_tol" in numeric
    numeric += ["parts_missed_pct", "delivered_of_bound_pct"]  # the shares, after the runs' own
    assert len(summary) == 4 * len(numeric)
    assert list(dict.fromkeys(summary["measure"])) == numeric
    for r in summary[summary["measure"] == "parts_per_hr_wallclock"].to_dict("records"):
        x = frame[(frame["policy"] == r["policy"]) & (frame["belts.output_nominal_in_s"]
                                                        == r["belts.output_nominal_in_s"])]
        x = x["parts_per_hr_wallclock"].to_numpy(float)
        lo, hi = scipy.stats.t.interval(0.95, x.size - 1, loc=x.mean(), scale=scipy.stats.sem(x))
        assert (r["ci_low"], r["ci_high"]) == pytest.approx((lo, hi), rel=1e-9)
    diffs = pd.read_csv(tmp_path / "rep" / "differences.csv")
    assert len(diffs) == 2 * len(numeric)
    files = sorted(p.name for p in (tmp_path / "rep").iterdir())
    assert "table_7_1.md" not in files and "report.md" in files
    assert [f for f in files if f.startswith("fig_")] == sorted(
        f"fig_{m}.png" for m in ("parts_delivered", "parts_missed", "parts_per_hr_wallclock",
                                 "actual_cycle_wallclock_s", "ip_wallclock",
                                 "spacing_outside_tol"))
    text = (tmp_path / "rep" / "report.md").read_text()
    for title in ("## Parts delivered", "## Parts lost", "## Parts per hour (wall clock)",
                  "## Actual cycle (wall clock, s)", "## IP (wall clock", "## Spacings outside",
                  "## Reading"):
        assert title in text


def test_a_sweep_of_only_the_policies_gets_a_point_per_policy(sweeps, tmp_path):
    sweep = load_sweep(sweeps.write(tmp_path, policies=["non-adaptive", "adaptive"],
                                   replications=4, batch=4))
    frame = run_sweep(sweep, tmp_path / "o", workers=1, replicate=known,
                      progress=False).replications
    summary, diffs = summary_table(frame, sweep), difference_table(frame, sweep)
    assert list(summary.columns[:2]) == ["policy", "measure"]
    d = diffs[diffs["measure"] == "parts_delivered"]
    assert len(d) == 1 and d["mean"].iloc[0] == pytest.approx(10.0, abs=1.0)


def test_baseline_point_differences(sweeps, tmp_path):
    path = small_sweep(sweeps, tmp_path, baseline={"policy": "non-adaptive",
                                           "belts.output_nominal_in_s": 2.0})
    sweep = load_sweep(path)
    frame = run_sweep(sweep, tmp_path / "o", workers=1, replicate=known,
                      progress=False).replications
    d = difference_table(frame, sweep)
    d = d[d["measure"] == "parts_per_hr_wallclock"]
    base = d[d["versus"] == "non-adaptive at belts.output_nominal_in_s = 2"]
    # three points against non-adaptive at 2.0: the output belt adds 4 x 0.5 = 2 parts/hr
    assert sorted(zip(base["policy"], base["belts.output_nominal_in_s"],
                      base["mean"].round(9))) == [
        ("adaptive", 2.0, 0.0), ("adaptive", 2.5, 2.0), ("non-adaptive", 2.5, 2.0)]
    # and, beside them, the policies against each other (issue 24): the same parts per hour
    # for both, as ``known`` gives them; at 2.0 that pair is the baseline's, given once
    pair = d[d["versus"] == "non-adaptive"]
    assert sorted(zip(pair["policy"], pair["belts.output_nominal_in_s"],
                      pair["mean"].round(9))) == [("adaptive", 2.5, 0.0)]
    assert len(d) == len(base) + len(pair)


# --------------------------------------------------------------------------- the what-if
def test_whatif_arrivals_are_5_percent_faster_with_twice_the_spread():
    doc = yaml.safe_load((catalog.BUILT_IN / "whatif.yaml").read_text())
    params = doc["grid"]["arrivals.params"]
    thesis = scipy.stats.weibull_min(**params["thesis"])
    assert params["thesis"] == {"c": 1 / 0.2038, "loc": 17.6019, "scale": 5.4342}  # eq. 6.9
    for name, mean, sd in (("faster", 0.95, 1.0), ("wider", 1.0, 2.0), ("both", 0.95, 2.0)):
        d = scipy.stats.weibull_min(**params[name])
        assert params[name]["c"] == params["thesis"]["c"]  # the same shape
        assert d.mean() / thesis.mean() == pytest.approx(mean, rel=1e-12)
        assert d.std() / thesis.std() == pytest.approx(sd, rel=1e-12)
    sweep = load_sweep(catalog.BUILT_IN / "whatif.yaml")
    assert {p.policy for p in sweep.points} == {"non-adaptive", "adaptive"}
    assert sweep.baseline is not None and sweep.baseline.names == (("arrivals.params", "thesis"),)


def columns(table: str) -> list[str]:
    """The column names of the first markdown table in ``table``."""
    header = next(line for line in table.splitlines() if line.startswith("|"))
    return [cell.strip() for cell in header.strip("|").split("|")]


def _row(table: pd.DataFrame, **where) -> pd.Series:
    sel = table
    for k, v in where.items():
        sel = sel[sel[k.replace("__", ".")] == v]
    assert len(sel) == 1, where
    return sel.iloc[0]


def test_two_varied_keys_give_a_table_row_per_combination_and_panels(sweeps, tmp_path):
    path = sweeps.write(tmp_path, grid={"belts.output_nominal_in_s": [2.0, 2.5],
                                       "belts.input_nominal_in_s": [2.5, 3.0]},
                       policies=["non-adaptive", "adaptive"], replications=3, batch=3)
    sweep = load_sweep(path)
    frame = run_sweep(sweep, tmp_path / "o", workers=1, replicate=known,
                      progress=False).replications
    paths = write_report(frame, sweep, plan_report(sweep, tmp_path / "rep"), "test")
    text = (tmp_path / "rep" / "report.md").read_text()
    table = text.split("## Parts delivered")[1].split("\n## ")[0]
    assert columns(table) == ["belts.output_nominal_in_s", "belts.input_nominal_in_s",
                              "non-adaptive", "adaptive", "adaptive − non-adaptive"]
    assert len([line for line in table.splitlines() if line.startswith("| 2")]) == 4
    assert (tmp_path / "rep" / "fig_parts_delivered.png") in paths
    assert len(pd.read_csv(tmp_path / "rep" / "differences.csv")) == 4 * 3  # 4 pairs x 3
