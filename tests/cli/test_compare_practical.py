"""``cell compare``'s overall verdict weighs practical size (issue 35, item 5): a difference
the interval shows but that is trivially small in parts per 1,000 does not make the verdict
mixed; the largest practical difference decides; OEE is weighed too; and a fitted scenario is
compared with the trace it was fitted to although their mean inter-arrival times differ by less
than the trace's own sampling error."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cell.cli.main import main
from cell.experiments.sweep.spec import comparison
from cell.reporting.compare_judgement import judgement, verdict
from cell.reporting.compare_rates import rate_error_s, rates_differ
from cell.reporting.compare_verdict import Judged, decide
from cell.scenario.schema import load_scenario

pytestmark = pytest.mark.usefixtures("unlaid")

A, B = "good-sensor", "cheap-sensor"
#: Both sides' means: A delivers 177 parts more of 500 arrived; B leaves 0.125 fewer spacings
#: off per run (0.25 per 1,000 parts delivered): the issue's "mixed (good-sensor better on 5,
#: cheap-sensor on 1)".
MEANS = {"parts_arrived": (500.0, 500.0), "parts_delivered": (490.0, 313.0),
         "parts_missed": (10.0, 187.0), "parts_per_hr_wallclock": (158.0, 101.0),
         "actual_cycle_wallclock_s": (22.7, 35.6), "ip_wallclock": (0.995, 0.64),
         "spacing_outside_tol": (0.125, 0.0), "oee": (0.80, 0.51),
         "mean_interarrival_s": (22.5872, 22.5872)}
#: Parts delivered, lost, per hour and the cycle: one throughput, four ways.
THROUGHPUT = {"Parts delivered", "Parts lost (wall clock)", "Parts per hour (wall clock)",
              "Actual cycle (wall clock, s)"}
#: (mean, half-width) of A - B: every one shown (the interval excludes 0).
DIFFS = {"parts_delivered": (177.0, 3.0), "parts_missed": (-177.0, 3.0),
         "parts_per_hr_wallclock": (57.0, 1.0), "actual_cycle_wallclock_s": (-12.9, 0.3),
         "ip_wallclock": (0.355, 0.01), "spacing_outside_tol": (0.125, 0.1),
         "oee": (0.29, 0.01)}


def tables(means=MEANS, diffs=DIFFS):
    summary = pd.DataFrame([
        {"scenario": s, "policy": "adaptive", "measure": m, "n": 30, "mean": pair[i], "sd": 1.0,
         "ci_low": pair[i] - 1, "ci_high": pair[i] + 1, "run_p2_5": 0, "run_p97_5": 1}
        for i, s in enumerate((A, B)) for m, pair in means.items()])
    differences = pd.DataFrame([
        {"scenario": A, "policy": "adaptive", "versus": B, "measure": m, "n": 30, "mean": d,
         "sd": 2.0, "ci_low": d - h, "ci_high": d + h, "p_value": 0.01}
        for m, (d, h) in diffs.items()])
    return summary, differences


@pytest.fixture(scope="module")
def sweep():
    s = load_scenario("baseline")
    return comparison(s, s.with_overrides({"sensor.lookahead": "sensor"}), (A, B), 30, 1)


def test_a_trivial_difference_does_not_make_the_verdict_mixed(sweep):
    _, v = judgement(*tables(), sweep)
    assert [j.title for j in v.judged if j.side < 0] == ["Spacings outside 45 ± 0.25 in"]
    assert v.winner == A and v.better == 1
    assert v.deciding in THROUGHPUT  # 177 of 500 arrived: 354 per 1,000
    assert v.size("Parts delivered") == pytest.approx(354.0)
    # the same throughput in parts per hour and as a cycle: about the same size, per 1,000
    # arrivals (159.4 an hour)
    assert v.size("Parts per hour (wall clock)") == pytest.approx(57 * 22.5872 / 3.6)
    assert v.size("Actual cycle (wall clock, s)") == pytest.approx(
        1000 * 22.5872 * (1 / 22.7 - 1 / 35.6))
    assert max(v.size(t) for t in THROUGHPUT) < 1.1 * min(v.size(t) for t in THROUGHPUT)
    assert v.against == ()  # nothing practical the other way
    assert v.trivial == ("Spacings outside 45 ± 0.25 in",)
    # 0.125 spacings of the 401.5 parts delivered on average: 0.31 per 1,000
    assert v.size("Spacings outside 45 ± 0.25 in") == pytest.approx(1000 * 0.125 / 401.5)
    assert "mixed" not in verdict(*tables(), sweep).splitlines()[-1]


def test_a_practical_difference_the_other_way_is_a_trade_off_the_larger_one_decides(sweep):
    """B 5 spacings off per run better (about 12 per 1,000 delivered): practical, so named
    against A; A's 177 more parts still decide.  With --practical above 12, it is trivial."""
    diffs = {**DIFFS, "spacing_outside_tol": (5.0, 0.5)}
    _, v = judgement(*tables(diffs=diffs), sweep)
    assert (v.winner, v.against) == (A, ("Spacings outside 45 ± 0.25 in",))
    assert v.deciding in THROUGHPUT
    _, lenient = judgement(*tables(diffs=diffs), sweep, practical=20.0)
    assert (lenient.winner, lenient.against, lenient.trivial) == \
        (A, (), ("Spacings outside 45 ± 0.25 in",))


def test_only_trivial_differences_are_no_practical_difference(sweep):
    """A 0.2-part difference in 500 (0.4 per 1,000) on every count, and nothing else shown."""
    small = {"parts_delivered": (0.2, 0.1), "parts_missed": (-0.2, 0.1)}
    means = {**MEANS, "parts_delivered": (400.1, 399.9), "parts_missed": (99.9, 100.1)}
    _, v = judgement(*tables(means, small), sweep)
    assert v.better == 0 and v.winner is None and v.deciding is None
    assert set(v.trivial) == {"Parts delivered", "Parts lost (wall clock)"}


@pytest.mark.parametrize(("sizes", "winner", "deciding"), [
    ([("x", 1, 0.5), ("y", -1, 0.9)], None, None),  # both below 1 per 1,000
    ([("x", 1, 5.0), ("y", -1, 50.0)], "b", "y"),
    ([("x", 1, math.nan), ("y", -1, 0.5)], "a", "x"),  # no common unit: counted as practical
    ([("x", 0, 500.0), ("y", -1, 2.0)], "b", "y"),  # a large estimate the interval does not show
])
def test_the_largest_practical_difference_decides(sizes, winner, deciding):
    v = decide([Judged(*s) for s in sizes], "a", "b", 1.0)
    assert (v.winner, v.deciding) == (winner, deciding)


def test_oee_is_weighed_and_said(sweep):
    lines, v = judgement(*tables(), sweep)
    oee = next(j for j in v.judged if j.title.startswith("OEE"))
    assert oee.side == 1 and oee.size_per_1000 == pytest.approx(290.0)
    assert any(line.strip().startswith("OEE") for line in lines)


def test_a_real_compare_says_oee_and_no_nan(capsys):
    assert main(["compare", "baseline", "non_adaptive", "--set", "run.parts=30",
                 "--replications", "3", "--workers", "1"]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if line.strip().startswith("OEE"))
    assert "better" in row and "nan" not in out.lower()
    # where each side's planned busy time went, by summary.csv's names, A's share first
    losses = next(line for line in out.splitlines() if line.strip().startswith("OEE losses"))
    shares = dict(re.findall(r"(loss_\w+) ([-\d.]+)% against", losses))
    assert list(shares) == ["loss_downtime", "loss_starved", "loss_blocked", "loss_speed",
                            "loss_quality"]
    assert shares["loss_downtime"] == "0.0" and float(shares["loss_starved"]) > 0


@pytest.mark.parametrize("practical", ["-1", "nan", "inf"])
def test_a_bad_practical_threshold_is_refused_before_running(tmp_path, capsys, practical):
    out = tmp_path / "o"
    assert main(["compare", "baseline", "non_adaptive", "--practical", practical,
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and f"--practical {float(practical)}" in err
    assert not out.exists()


def trace(tmp_path: Path, n: int = 400) -> tuple[Path, np.ndarray]:
    times = np.random.default_rng(7).gamma(1 / 0.3**2, 22.5872 * 0.3**2, n)
    path = tmp_path / "trace.csv"
    path.write_text("interarrival_s\n" + "\n".join(f"{t:.6f}" for t in times) + "\n")
    return path, np.loadtxt(path, skiprows=1)


def test_a_traces_rate_error_is_its_samples(tmp_path):
    path, times = trace(tmp_path)
    s = load_scenario("baseline", {"arrivals.trace_csv": str(path)})
    assert rate_error_s(s.arrivals, s.base_dir) == pytest.approx(
        np.std(times, ddof=1) / math.sqrt(len(times)), rel=1e-12)
    b = load_scenario("baseline")
    assert rate_error_s(b.arrivals, b.base_dir) == 0.0  # a distribution's mean is exact


@pytest.mark.parametrize(("apart", "differ"), [(5e-4, False), (0.05, True)])
def test_a_fit_is_judged_against_its_trace_within_the_traces_sampling_error(
        tmp_path, apart, differ):
    """The issue's 0.05 %: within the trace's sampling error (about 0.7 % here), the rates
    are the same and the counts judged; 5 % is a different demand."""
    _, times = trace(tmp_path)
    se = float(np.std(times, ddof=1) / math.sqrt(len(times)))
    mean = float(times.mean())
    summary = pd.DataFrame([{"scenario": s, "measure": "mean_interarrival_s", "mean": m}
                            for s, m in (("fit", mean * (1 + apart)), ("trace", mean))])
    said = rates_differ(summary, "fit", "trace", (0.0, se), 0.95)
    assert (said is not None) is differ
    assert rates_differ(summary, "fit", "trace") is not None  # no sampling error: they differ


def test_compare_of_a_fit_and_its_trace_judges_parts_delivered(tmp_path, capsys):
    path, times = trace(tmp_path, 60)
    fit = tmp_path / "fit.yaml"
    fit.write_text("name: fit\narrivals: {distribution: gamma, params: {}, mean_s: "
                   f"{float(times.mean()) * 1.0005!r}, cv: 0.3}}\n"
                   "controller: {nominal_cycle_s: null}\n")
    tr = tmp_path / "tr.yaml"
    tr.write_text(f"name: trace\narrivals: {{trace_csv: {path}}}\n"
                  "controller: {nominal_cycle_s: null}\n")
    assert main(["compare", str(fit), str(tr), "--set", "run.parts=40", "--replications", "3",
                 "--workers", "1", "--policy", "non-adaptive"]) == 0
    out = capsys.readouterr().out
    assert "not judged" not in out and "rate-free" not in out


def test_a_compare_with_costs_and_energy_says_them_and_weighs_only_parts(tmp_path, capsys):
    """With ``costs:`` and ``energy:`` on both sides the verdict says each money and energy
    measure's paired difference (lower is better), signed as differences.csv has it; the
    overall line still weighs the parts measures only (its count of measures is unchanged)."""
    money = ("--set", 'energy={power_w: {robot: {busy: 120, waiting: 40, idle: 40}}}',
             "--set", "costs={part_value: 12.0, energy_per_kwh: 0.2}")
    common = ["--set", "run.parts=30", "--replications", "3", "--workers", "1"]
    assert main(["compare", "baseline", "non_adaptive", *common]) == 0
    plain = capsys.readouterr().out.splitlines()
    assert main(["compare", "baseline", "non_adaptive", *common, *money,
                 "--out", str(tmp_path / "c")]) == 0
    said = capsys.readouterr().out.splitlines()
    diffs = pd.read_csv(tmp_path / "c" / "differences.csv").set_index("measure")["mean"]
    for title, column in (("Cost per good part", "cost_per_good_part"),
                          ("Cost per hour", "cost_per_h"),
                          ("Energy per good part (Wh)", "energy_per_good_part_wh")):
        line = next(x for x in said if x.strip().startswith(title))
        a_lower = diffs[column] < 0
        assert ("baseline better" in line) == a_lower and ("non_adaptive better" in line) != a_lower
    assert not any(x.strip().startswith("Cost") for x in plain)  # only where costs are given
    overall = [next(x for x in out if x.startswith("Overall")) for out in (said, plain)]
    assert overall[0].split("(")[-1] == overall[1].split("(")[-1]  # the same measures weighed
