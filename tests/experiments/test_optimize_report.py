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
    one point best in both objectives, feasible; every trial slower than it breaks a
    constraint; KN eliminates that point in favour of the trial it chose."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    front, trials = (pd.read_csv(OPT / f) for f in ("front.csv", "trials.csv"))
    sel = pd.read_csv(OPT / "selection.csv")
    points = front.drop_duplicates(["belts.input_nominal_in_s", "controller.nominal_cycle_s"])
    assert len(points) == 1 and "no trade-off" in text
    row = points.iloc[0]
    assert row["feasible"] and row["parts_missed"] <= 1 and row["spacing_outside_pct"] <= 1
    slower = trials[trials["belts.input_nominal_in_s"] < row["belts.input_nominal_in_s"]]
    assert len(slower) and not slower["feasible"].any()
    assert sel[sel["trial"] == row["trial"]].iloc[0]["verdict"] == "eliminated"
    assert (sel["verdict"] == "chosen").sum() == 1


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
