"""README's worked example reads reports/optimize (make optimize) as it is, and the sensitivity
report's reading must follow from its own tables."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[2]
OPT = ROOT / "reports" / "optimize"
SENS = ROOT / "reports" / "sensitivity"


def test_the_worked_example_is_what_the_committed_report_says() -> None:
    """The README's reading of reports/optimize (its numbers: tests/reporting/test_readme.py):
    the best trial is the cheapest feasible one and KN tells none of its candidates apart; a
    trial's cost per hour is its cost per good part times its good parts per hour; a longer
    nominal cycle asks more of R IV and of the drives, and loses parts."""
    import yaml

    trials, best = (pd.read_csv(OPT / f) for f in ("trials.csv", "best.csv"))
    sel = pd.read_csv(OPT / "selection.csv")
    feasible = trials[trials["feasible"]]
    row = best.iloc[0]
    assert row["cost_per_good_part"] == feasible["cost_per_good_part"].min()
    assert row["parts_missed"] <= 1 and row["spacing_outside_pct"] <= 1
    assert set(sel["verdict"]) == {"chosen", "alike"} and (sel["verdict"] == "chosen").sum() == 1
    # no part lost: every part delivered is good (quality.rule: set_down), so cost an hour =
    # cost a good part x parts an hour, to the replications' spread (means of ratios)
    whole = feasible[feasible["parts_missed"] == 0]
    assert len(whole) > 10
    rel = (whole["cost_per_good_part"] * whole["parts_per_hr_wallclock"] / whole["cost_per_h"] - 1).abs()
    assert rel.max() < 0.01
    # options an hour (robot + adaptive controller) are nearly all of a part's cost
    prices = yaml.safe_load((ROOT / "scenarios" / "costed.yaml").read_text())["costs"]["options_per_h"]
    assert (whole["cost_per_h"] - prices["robot"] - prices["adaptive_controller"]).between(0, 0.1).all()
    cycle = trials[trials["refused"].isna()]["controller.nominal_cycle_s"]
    ran = trials[trials["refused"].isna()]
    short, long = ran[cycle <= 22.25], ran[cycle >= 24.75]
    for measure in ("vavg_r4_in_s", "arm_energy_per_transfer_j", "energy_per_good_part_wh",
                    "parts_missed"):
        assert long[measure].mean() > short[measure].mean(), measure


def test_the_sensitivity_reading_follows_from_its_tables() -> None:
    report = (SENS / "report.md").read_text(encoding="utf-8")
    points = pd.read_csv(SENS / "points.csv")
    sobol = pd.read_csv(SENS / "sobol.csv")
    adv = points["advantage"]
    if (adv > 0).all():
        assert "The thesis's conclusion holds" in report
        assert f"at every one of the {len(points)} points" in report
    else:
        assert "is reversed" in report
    # every key of scenarios/assumptions.yaml is screened; the roll, which does not turn on
    # the path, moves nothing
    morris = pd.read_csv(SENS / "morris.csv")
    roll = morris[morris["key"] == "robot.motors.max_rate_no_load_rad_s[4]"]
    assert len(roll) and (roll["mu_star"] < 1e-6).all()
    assert set(sobol["key"]) <= set(morris["key"])


@pytest.mark.parametrize("name", ["optimize.yaml", "assumptions.yaml"])
def test_the_shipped_studies_load(name: str) -> None:
    from cell.experiments.study import load_study

    study = load_study(ROOT / "scenarios" / name, corners=False)
    assert study.params
