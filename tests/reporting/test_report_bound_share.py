"""Parts delivered as a share of the bound in a sweep's report (issue 22, item 4): each
run's ``parts_delivered`` over its ``parts_bound`` (cell/sim/bound.py), from the same runs,
never above 100 %, per policy, with its interval over the replications, beside parts
delivered in report.md."""

from __future__ import annotations

import numpy as np
import pytest

from cell.experiments.sweep import load_sweep, run_sweep
from cell.reporting.experiment.data import BOUND_SHARE, with_bound_share
from cell.reporting.experiment.report import difference_table, summary_table
from cell.reporting.experiment.text import markdown
from tests.prose import in_order


@pytest.fixture(scope="module")
def report(sweeps, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bound")
    faster = {"run.parts": 24, "arrivals.distribution": "gamma", "arrivals.mean_s": 12.0,
              "arrivals.cv": 0.3, "controller.nominal_cycle_s": None}  # faster than the robot
    sweep = load_sweep(sweeps.write(tmp, set=faster, replications=4, batch=4))
    frame = run_sweep(sweep, tmp / "o", workers=1, progress=False,
                      warn_windows=False).replications
    summary, differences = summary_table(frame, sweep), difference_table(frame, sweep)
    return sweep, frame, summary, differences, markdown(summary, differences, frame, sweep,
                                                        "cell sweep", [])


def test_the_share_is_delivered_over_the_bound_of_the_same_runs(report):
    sweep, frame, summary, differences, _ = report
    assert BOUND_SHARE not in frame  # replications.csv stays as the runs gave it
    share = summary[summary["measure"] == BOUND_SHARE]
    assert len(share) == len(sweep.points) and set(share["policy"]) == set(sweep.policies)
    for p, row in zip(sweep.points, share.to_dict("records"), strict=True):
        runs = frame[(frame["policy"] == p.policy) & (frame["point"] == p.index)]
        by_hand = 100.0 * runs["parts_delivered"].to_numpy(float) / runs["parts_bound"]
        assert (runs["parts_bound"] > 0).all() and (by_hand <= 100.0).all()  # a bound
        assert (runs["parts_bound"] < runs["parts_arrived"]).any()  # not the service level
        assert row["policy"] == p.policy and row["n"] == len(runs)
        assert row["mean"] == pytest.approx(by_hand.mean(), rel=1e-12) and row["mean"] <= 100.0
    # the fixed cycles of 22 and 21 s deliver fewer than the adaptive robot, which is itself
    # held below the bound by the belts it shares
    means = share.set_index("policy")["mean"]
    assert means["non-adaptive"].max() < means["adaptive"] <= 100.0
    paired = differences[differences["measure"] == BOUND_SHARE]
    assert len(paired) == 2 and (paired["versus"] == "non-adaptive").all()


def test_report_shows_the_share_beside_each_policys_deliveries(report):
    _, _, summary, _, text = report
    section = text.split("## Parts delivered")[1].split("\n## ")[0]
    rows = [x.split(" | ") for x in section.splitlines() if x.startswith("| ")]
    head = rows[0]
    assert head[2:7] == ["non-adaptive", "of bound %", "adaptive", "of bound %",
                         "adaptive − non-adaptive |"]
    by_key = {(f"{r['controller.ideal_cycle_s']:g}", r["policy"]): r for r in
              summary[summary["measure"] == BOUND_SHARE].to_dict("records")}
    for row in rows[2:]:
        for at, policy in ((3, "non-adaptive"), (5, "adaptive")):
            if (row[0].strip("| "), policy) not in by_key:
                assert row[at] == ""
                continue
            r, shown = by_key[row[0].strip("| "), policy], row[at].split(" ")[0]
            places = len(shown.partition(".")[2])
            assert abs(float(shown) - r["mean"]) <= 0.5 * 10.0 ** -places + 1e-9, (row, r)
            assert float(shown) <= 100.0
    assert in_order(section, "of bound %:", "parts delivered", "`parts_bound`")  # the column, defined
    for other in ("## Parts lost", "## Parts per hour"):  # the other tables as they were
        assert "of bound" not in text.split(other)[1].split("\n## ")[0]


def test_no_bound_no_share():
    import pandas as pd

    old = pd.DataFrame({"parts_delivered": [3, 4]})  # a sweep's results from before the bound
    assert with_bound_share(old) is old
    zero = with_bound_share(pd.DataFrame({"parts_delivered": [0, 2], "parts_bound": [0, 4]}))
    assert np.isnan(zero[BOUND_SHARE][0]) and zero[BOUND_SHARE][1] == 50.0


def test_the_summary_has_parts_lost_as_a_share_of_arrivals_as_optimize_reports_it(report):
    """Issue 35 item 5: a sweep's summary has ``parts_missed_pct``, the measure cell optimize
    and the studies report, run by run from the same runs (the bound's share stays last)."""
    from cell.experiments.study import measures_of
    from cell.reporting.experiment.data import MISSED_SHARE

    sweep, frame, summary, differences, _ = report
    assert MISSED_SHARE == "parts_missed_pct" and MISSED_SHARE not in frame
    share = summary[summary["measure"] == MISSED_SHARE]
    assert len(share) == len(sweep.points)
    lost_some = False
    for p, row in zip(sweep.points, share.to_dict("records"), strict=True):
        runs = frame[(frame["policy"] == p.policy) & (frame["point"] == p.index)]
        by_hand = 100.0 * runs["parts_missed"].to_numpy(float) / runs["parts_arrived"]
        assert row["mean"] == pytest.approx(by_hand.mean(), rel=1e-12, abs=1e-12)
        assert row["mean"] == pytest.approx(np.mean(
            [measures_of(r)[MISSED_SHARE] for r in runs.to_dict("records")]), rel=1e-12, abs=1e-12)
        lost_some |= row["mean"] > 0
    assert lost_some  # arrivals faster than the robot: parts are lost
    assert len(differences[differences["measure"] == MISSED_SHARE]) == 2
    order = list(dict.fromkeys(summary["measure"]))
    assert order[-2:] == [MISSED_SHARE, BOUND_SHARE]
