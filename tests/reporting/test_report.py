"""Table 7.1 beside the thesis (thesis §7.2; docs/accounting.md): statistics, layout, reading."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
import scipy.stats
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.experiments.sweep import load_sweep, run_sweep
from cell.plumbing.errors import CellError
from cell.reporting.table_7_1.table import (
    COLUMNS,
    markdown,
    reading,
    statistics,
    summary_column,
    table_7_1,
    table_7_1_files,
    thesis_value,
)
from cell.scenario import catalog
from tests.prose import in_order

# Table 7.1 as printed (thesis §7.2; docs/accounting.md): cycle, actual, missed, parts/hr, Vavg R IV, IP.
PUBLISHED = [
    (22.5872, 54.1660, 206, 66.4624, 3.5594, 0.3901),
    (22.0000, 35.6057, 113, 101.1074, 3.7818, 0.4388),
    (21.5000, 29.0548, 64, 123.9039, 3.9943, 0.4655),
    (21.0000, 25.8622, 35, 139.1995, 4.2321, 0.4817),
    (20.5000, 23.8200, 14, 151.1336, 4.5000, 0.4933),
    (20.0907, 23.0209, 5, 156.3796, 4.7459, 0.4984),
]


def test_t_interval_and_run_percentiles_closed_form():
    s = statistics([1.0, 2.0, 3.0, 4.0, 5.0])
    # mean 3, sd sqrt(2.5), t(0.975, 4) = 2.776445
    half = 2.776445105 * math.sqrt(2.5) / math.sqrt(5)
    assert s["mean"] == 3.0
    assert s["ci_low"] == pytest.approx(3 - half, abs=1e-8)
    assert s["ci_high"] == pytest.approx(3 + half, abs=1e-8)
    # linear interpolation between order statistics: rank 0.025*4 = 0.1, 0.975*4 = 3.9
    assert (s["run_p2_5"], s["run_p97_5"]) == pytest.approx((1.1, 4.9))


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3), min_size=2, max_size=60))
def test_interval_holds_the_mean_and_matches_scipy(values):
    s = statistics(values)
    x = np.asarray(values)
    assert s["ci_low"] <= s["mean"] + 1e-9 and s["mean"] <= s["ci_high"] + 1e-9
    assert s["run_p2_5"] >= x.min() - 1e-9 and s["run_p97_5"] <= x.max() + 1e-9
    if x.std() > 1e-6 * max(1.0, abs(x.mean())):
        lo, hi = scipy.stats.t.interval(0.95, x.size - 1, loc=x.mean(), scale=scipy.stats.sem(x))
        assert (s["ci_low"], s["ci_high"]) == pytest.approx((lo, hi), rel=1e-9, abs=1e-9)


def test_constant_measure_has_a_degenerate_interval():
    s = statistics([4.5] * 10)
    assert s["ci_low"] == s["ci_high"] == s["mean"] == s["run_p2_5"] == s["run_p97_5"] == 4.5


def test_published_values_are_thesis_accounting_only():
    for cycle, *row in PUBLISHED:
        for measure, value in zip(("actual_cycle_s", "parts_missed", "parts_per_hr",
                                   "vavg_r4_in_s", "ip"), row, strict=True):
            assert thesis_value("non-adaptive", cycle, "thesis", measure) == value
            assert math.isnan(thesis_value("non-adaptive", cycle, "wallclock", measure))
    assert thesis_value("adaptive", 22.5872, "thesis", "ip") == 1.0214  # §7.2
    assert thesis_value("adaptive", 22.5872, "thesis", "parts_missed") == 0
    assert math.isnan(thesis_value("non-adaptive", 19.0, "thesis", "ip"))


def test_summary_columns_follow_the_simulation_names():
    cols = ["actual_cycle_thesis_s", "actual_cycle_wallclock_s", "parts_missed", "ip_thesis"]
    assert summary_column("thesis", "actual_cycle_s", cols) == "actual_cycle_thesis_s"
    assert summary_column("wallclock", "parts_missed", cols) == "parts_missed"
    with pytest.raises(CellError, match="ip_wallclock"):
        summary_column("wallclock", "ip", cols)


@pytest.fixture(scope="module")
def thesis_table(sweeps, tmp_path_factory):
    """The Table 7.1 sweep on the reconstructed bookkeeping of docs/accounting.md (200 x 500 parts)."""
    tmp = tmp_path_factory.mktemp("t71")
    sweep = load_sweep(catalog.BUILT_IN / "table_7_1.yaml")
    frame = run_sweep(sweep, tmp / "out", workers=1, replicate=sweeps.bookkeeping,
                      progress=False).replications
    return sweep, frame, table_7_1(frame, sweep)


def test_long_form_has_exactly_the_columns_and_rows(thesis_table):
    _sweep, _frame, table = thesis_table
    assert list(table.columns) == COLUMNS
    assert len(table) == 7 * 2 * 5
    assert list(dict.fromkeys(table["policy"])) == ["non-adaptive", "adaptive"]
    assert set(table["accounting"]) == {"thesis", "wallclock"}
    assert set(table["measure"]) == {"actual_cycle_s", "parts_missed", "parts_per_hr",
                                     "vavg_r4_in_s", "ip"}
    na = table[table["policy"] == "non-adaptive"]
    assert list(dict.fromkeys(na["ideal_cycle_s"])) == [r[0] for r in PUBLISHED]
    assert set(table.loc[table["policy"] == "adaptive", "ideal_cycle_s"]) == {22.5872}
    assert (table["ci_low"] <= table["mean"] + 1e-12).all()
    assert (table["mean"] <= table["ci_high"] + 1e-12).all()


def test_the_thesis_bookkeeping_puts_the_thesis_inside_single_run_ranges(thesis_table):
    """docs/accounting.md: s = 0.23 s reproduces the random columns in all six rows; this checks
    the report matches each published figure to its own row and measure."""
    _sweep, _frame, table = thesis_table
    t = table[(table["policy"] == "non-adaptive") & (table["accounting"] == "thesis")]
    for measure in ("parts_missed", "actual_cycle_s", "ip"):
        rows = t[t["measure"] == measure]
        assert len(rows) == 6
        assert ((rows["run_p2_5"] <= rows["thesis"]) & (rows["thesis"] <= rows["run_p97_5"])).all()
    v = t[t["measure"] == "vavg_r4_in_s"]
    assert (abs(v["mean"] - v["thesis"]) < 2e-4).all()


def test_markdown_puts_the_thesis_beside_ours_and_reads_from_the_numbers(thesis_table):
    sweep, _frame, table = thesis_table
    text = markdown(table, sweep)
    for cycle, actual, missed, pph, vavg, ip in PUBLISHED:
        row = next(line for line in text.splitlines() if line.startswith(f"| {cycle:.4f} |"))
        for fig in (f"{actual:.4f}", f"| {missed} |", f"{pph:.4f}", f"{vavg:.4f}", f"{ip:.4f}"):
            assert fig in row
    assert "1.0214" in text
    top = table[(table["policy"] == "non-adaptive") & (table["ideal_cycle_s"] == 22.5872)]
    missed = top[(top["accounting"] == "thesis") & (top["measure"] == "parts_missed")]
    assert f"loses {missed['mean'].iloc[0]:.1f} of 500 parts" in text
    assert "18 of 18 cases" in text


def test_markdown_of_hours_long_runs_names_no_parts_count(thesis_table):
    """The same table from runs of run.hours: said to be of hours, with no count of parts a run
    (run.parts' default, 500, is not what such a run brings) and no share of it lost."""
    from types import SimpleNamespace

    from cell.scenario.schema import load_scenario

    sweep, _frame, table = thesis_table
    hours = SimpleNamespace(points=[SimpleNamespace(scenario=load_scenario("baseline", {"run.hours": 2}))],
                            replications=sweep.replications, source=sweep.source, seed=sweep.seed)
    text = markdown(table, hours)
    assert f"{sweep.replications} replications of 2 hours per row" in text
    assert "of 500 parts" not in text and "of the parts are lost" not in text
    assert "of the parts are lost" in markdown(table, sweep)


def _synthetic(thesis_missed: float, wall_missed: float) -> pd.DataFrame:
    rows = []
    for cycle in (22.5872, 20.0907):
        for acc, missed, actual, ip in (("thesis", thesis_missed, 50.0, 0.4),
                                        ("wallclock", wall_missed, 30.0, 0.8)):
            for m, v in (("actual_cycle_s", actual), ("parts_missed", missed),
                         ("parts_per_hr", 3600 / actual), ("vavg_r4_in_s", 3.5594), ("ip", ip)):
                rows.append({"policy": "non-adaptive", "ideal_cycle_s": cycle, "accounting": acc,
                             "measure": m, "thesis": thesis_value("non-adaptive", cycle, acc, m),
                             "mean": v, "ci_low": v, "ci_high": v, "run_p2_5": v,
                             "run_p97_5": v})
    return pd.DataFrame(rows, columns=COLUMNS)


def test_reading_follows_the_direction_of_the_numbers():
    more = " ".join(reading(_synthetic(200.0, 160.0), 500))
    same = " ".join(reading(_synthetic(200.0, 200.0), 500))
    fewer = " ".join(reading(_synthetic(5.0, 10.0), 500))
    assert in_order(more, "loses 200.0 of 500 parts", "against 160.0")  # thesis against wall clock
    assert "cannot come twice running" in more and "same number" not in more
    assert "same number of parts" in same and "twice running" not in same
    assert "loses fewer than the wall clock" in fewer and "twice running" not in fewer
    assert "2.00–2.00 times lower" in more  # 0.8 / 0.4
    assert "+66.7%" in more  # actual cycle 50 s against 30 s


def test_the_report_writes_both_table_7_1_files(sweeps, tmp_path, unlaid):
    """A Table 7.1 sweep's report holds table_7_1.csv (the long form, read back whole) and
    table_7_1.md, as :func:`table_7_1_files` makes them."""
    from cell.reporting.experiment.report import plan_report, write_report

    sweep = load_sweep(sweeps.write(tmp_path, set={"run.parts": 500}))  # laid out like Table 7.1
    frame = run_sweep(sweep, tmp_path / "o", workers=1, replicate=sweeps.bookkeeping,
                      progress=False).replications
    paths = write_report(frame, sweep, plan_report(sweep, tmp_path / "rep"), "test")
    csv, md = tmp_path / "rep" / "table_7_1.csv", tmp_path / "rep" / "table_7_1.md"
    assert {csv, md} <= set(paths)
    table, text = table_7_1_files(frame, sweep)
    assert md.read_text(encoding="utf-8") == text
    back = pd.read_csv(csv)
    assert len(back) == len(table)
    assert list(back.columns) == COLUMNS
    assert back.loc[back["accounting"] == "wallclock", "thesis"].isna().all()


def test_memoryless_reading_follows_the_numbers():
    """The adaptive reading says whether the memoryless IP holds the published 1.0214."""
    import numpy as np
    import pandas as pd

    from cell.reporting.table_7_1.table import memoryless as _memoryless

    rng = np.random.default_rng(0)
    near = pd.DataFrame({"policy": "adaptive", "ip_thesis_memoryless": 1.0214 + rng.normal(0, 1e-3, 200),
                         "cycle_vs_nominal_memoryless_pct": -2.0})
    far = near.assign(ip_thesis_memoryless=1.0 + rng.normal(0, 1e-3, 200))
    assert "1.0214 is inside" in _memoryless(near, 1.0214, "adaptive")[0]
    assert "reproduces the published IP" in _memoryless(near, 1.0214, "adaptive")[0]
    assert "is outside" in _memoryless(far, 1.0214, "adaptive")[0]
    assert "does not reproduce" in _memoryless(far, 1.0214, "adaptive")[0]
    assert _memoryless(near.drop(columns="ip_thesis_memoryless"), 1.0214, "adaptive") == []


def test_published_figures_are_data_that_route_the_layout(monkeypatch):
    """What the thesis published per policy decides the tables and the reading."""
    from cell.reporting import published as thesis
    from cell.reporting.table_7_1.sentences import reading_by_cycle, reading_one_run
    from cell.reporting.table_7_1.table import LAYOUTS

    assert set(LAYOUTS) == set(thesis.PUBLISHED) == {"non-adaptive", "adaptive"}
    for policy, layout in LAYOUTS.items():
        assert layout.published is thesis.PUBLISHED[policy]
        expected = reading_by_cycle if layout.published.by_cycle else reading_one_run
        assert layout.reading is expected
    assert thesis.PUBLISHED["adaptive"].value(21.0, "ip") == 1.0214  # one run, any cycle
    patched = {**thesis.PUBLISHED, "adaptive": thesis.Published({}, {"ip": 0.5}, "x")}
    monkeypatch.setattr(thesis, "PUBLISHED", patched)
    assert thesis_value("adaptive", 22.5872, "thesis", "ip") == 0.5
