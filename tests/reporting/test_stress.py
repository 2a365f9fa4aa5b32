"""The stress map (cell.reporting.maps.stress): its figures against scipy, its verdicts against
their intervals, and the committed reports/stress against the claim it reads."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import scipy.stats

from cell.experiments.sweep import load_sweep
from cell.reporting.maps.stress import reading, table, verdict, write
from cell.scenario import catalog
from tests.prose import in_order

ROOT = catalog.BUILT_IN.parent.parent


def synthetic(rng: np.random.Generator, advantage: float, n: int = 12) -> pd.DataFrame:
    """Replications of one point: the fixed robot's deliveries, and the adaptive robot's
    as the same plus ``advantage`` and paired noise (common random numbers)."""
    base = rng.normal(330.0, 6.0, n)
    rows = []
    for policy, delivered in (("non-adaptive", base),
                              ("adaptive", base + advantage + rng.normal(0, 2.0, n))):
        for r, d in enumerate(delivered):
            rows.append({"policy": policy, "replication": r, "arrivals.distribution": "gamma",
                         "arrivals.cv": 0.5, "arrivals.mean_s": 19.8925, "parts_delivered": d,
                         "parts_missed": 500 - d, "parts_per_hr_wallclock": d / 2.0,
                         "fastest_cycle_s": 18.0841, "offered_load": 18.0841 / 19.8925,
                         "spacing_outside_tol": 0.0, "limit_input_floor": 1.0,
                         "limit_r4_peak": 2.0, "limit_r2_peak": 0.0, "limit_input_ceiling": 0.0,
                         "limit_output_floor": 0.0, "parts_held": 0.0, "parts_bound": 500.0,
                         "limit_output_ceiling": 0.0, "limit_spacing_wait": 0.0,
                         "limit_spacing_unforeseen": 0.0})
    return pd.DataFrame(rows)


@pytest.mark.parametrize("advantage,expected", [(8.0, "better"), (0.0, "same"), (-8.0, "worse")])
def test_the_paired_interval_is_scipys_and_decides_the_verdict(advantage, expected):
    reps = synthetic(np.random.default_rng(3), advantage)
    t = table(reps)
    ad = t[t["policy"] == "adaptive"].iloc[0]
    a = reps[reps.policy == "adaptive"].sort_values("replication")["parts_delivered"].to_numpy()
    f = reps[reps.policy == "non-adaptive"].sort_values("replication")["parts_delivered"].to_numpy()
    ci = scipy.stats.ttest_rel(a, f).confidence_interval(0.95)
    assert (ad["delivered_vs_fixed_ci_low"], ad["delivered_vs_fixed_ci_high"]) == \
        pytest.approx((ci.low, ci.high), rel=1e-12)
    one = scipy.stats.t.interval(0.95, len(a) - 1, loc=a.mean(), scale=scipy.stats.sem(a))
    assert (ad["parts_delivered_ci_low"], ad["parts_delivered_ci_high"]) == \
        pytest.approx(one, rel=1e-12)
    assert verdict(ad) == expected
    assert ad["load"] == pytest.approx(1.1, abs=1e-4)


def test_the_reading_counts_what_the_table_shows():
    rng = np.random.default_rng(5)
    reps = pd.concat([synthetic(rng, 9.0), synthetic(rng, -9.0).assign(**{"arrivals.cv": 1.0})])
    text = " ".join(reading(table(reps)))
    assert in_order(text, "more parts than the fixed-cycle robot", "at 1 points")
    assert "fewer at 1 (gamma cv 1 load 1.10)" in text


def test_the_sweep_file_spans_the_map():
    """Means from overloaded (0.9 of the fastest cycle) to 30 % slack, cv 0.05 to 1, two or
    more families, both policies."""
    s = load_sweep("stress")
    fastest = 18.0841
    means = {p.scenario.arrivals.mean_s for p in s.points}
    assert min(means) / fastest == pytest.approx(0.9, abs=1e-4)
    assert max(means) / fastest == pytest.approx(1.3, abs=1e-4)
    assert {p.scenario.arrivals.cv for p in s.points} >= {0.05, 1.0}
    assert len({p.scenario.arrivals.distribution for p in s.points}) >= 2
    assert {p.policy for p in s.points} == {"adaptive", "non-adaptive"}


def test_the_committed_map_reads_what_its_csv_says(tmp_path):
    """reports/stress: the reading regenerated from the committed CSV is the committed one."""
    committed = ROOT / "reports" / "stress"
    t = pd.read_csv(committed / "stress.csv")
    text = (committed / "README.md").read_text(encoding="utf-8")
    for sentence in reading(t):
        assert sentence in text
    ad = t[t["policy"] == "adaptive"]
    assert (ad.apply(verdict, axis=1) != "worse").all()     # the claim, on this map


def test_written_as_a_set(tmp_path):
    reps = synthetic(np.random.default_rng(1), 5.0)
    path = tmp_path / "reps.csv"
    reps.to_csv(path, index=False)
    out = write(path, tmp_path / "stress")
    assert sorted(p.name for p in out.iterdir()) == ["README.md", "stress.csv", "stress.png"]
    assert (out / "stress.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_spacing_promise_is_read_with_its_causes():
    """A point (load 1.1, cv 0.5) where the adaptive robot sets 2 % of its parts off spacing,
    all after unforeseen waits: the reading names it, its share and the cause counted."""
    reps = synthetic(np.random.default_rng(2), 9.0)
    ad = reps["policy"] == "adaptive"
    reps.loc[ad, "spacing_outside_tol"] = 0.02 * reps.loc[ad, "parts_delivered"]
    reps.loc[ad, "limit_spacing_unforeseen"] = reps.loc[ad, "spacing_outside_tol"]
    text = " ".join(reading(table(reps)))
    assert in_order(text, "(more than 1 % at 1:", "gamma cv 0.5 load 1.10: 2.00 %")
    assert f"{reps.loc[ad, 'limit_spacing_unforeseen'].mean():.2f} a wait not foreseen" in text
    fine = synthetic(np.random.default_rng(2), 9.0)
    said = " ".join(reading(table(fine)))
    assert in_order(said, "at most 1 %", "holds at every one") and "more than 1 %" not in said


def test_the_bound_is_read_as_a_share():
    reps = synthetic(np.random.default_rng(4), 9.0)
    t = table(reps)
    share = t.set_index("policy")["delivered_vs_bound"]
    for policy in ("adaptive", "non-adaptive"):
        runs = reps[reps.policy == policy]
        assert share[policy] == pytest.approx(runs["parts_delivered"].sum() / 500.0 / len(runs))


@pytest.mark.parametrize("given", [[], ["only-one.csv"], ["a.csv", "b", "c"]])
def test_the_map_modules_refuse_a_wrong_count_of_arguments(given, monkeypatch, capsys):
    """``python -m cell.reporting.maps.stress`` wants the replications file and the folder:
    another count is one line and exit 2, never a traceback."""
    from cell.reporting.maps import map_report

    monkeypatch.setattr("sys.argv", ["stress", *given])
    with pytest.raises(SystemExit) as stop:
        map_report.command_line("cell.reporting.maps.stress", write, 2)
    err = capsys.readouterr().err.splitlines()
    assert stop.value.code == 2 and len(err) == 1 and f"given {len(given)}" in err[0]
