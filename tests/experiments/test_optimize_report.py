"""README's worked example quotes reports/optimize (make optimize); the numbers must be the
committed report's, and the sensitivity report's reading must follow from its own tables."""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[2]
OPT = ROOT / "reports" / "optimize"
SENS = ROOT / "reports" / "sensitivity"


def _example() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    return text[text.index("## Choosing a setting"):].split("\n## ", 1)[0]


def test_readme_worked_example_is_the_committed_report() -> None:
    text = _example()
    front = pd.read_csv(OPT / "front.csv")
    trials = pd.read_csv(OPT / "trials.csv")
    sel = pd.read_csv(OPT / "selection.csv")
    speed, cycle = (float(x) for x in re.search(
        r"as slowly as \*\*([\d.]+) in/s\*\* with a nominal cycle as long as\s+\*\*([\d.]+) s\*\*",
        text).groups())
    points = front.drop_duplicates(["belts.input_nominal_in_s", "controller.nominal_cycle_s"])
    assert len(points) == 1 and "no trade-off" in text  # one point best in both objectives
    row = points.iloc[0]
    assert (row["belts.input_nominal_in_s"], row["controller.nominal_cycle_s"]) == (speed, cycle)
    lost, off = (float(x) for x in re.search(r"losses ([\d.]+) parts of 500 on average, ([\d.]+) % "
                                             r"of spacings off", text).groups())
    assert round(row["parts_missed"], 1) == lost and round(row["spacing_outside_pct"], 2) == off
    assert row["feasible"] and row["parts_missed"] <= 1 and row["spacing_outside_pct"] <= 1
    # slower than the answer, every trial broke a constraint
    slower = trials[trials["belts.input_nominal_in_s"] < speed]
    assert len(slower) and not slower["feasible"].any()
    at_110 = re.search(r"at 1\.10 in/s already ([\d.]+) on average", text)
    assert at_110 and float(at_110[1]) in set(trials.loc[
        trials["belts.input_nominal_in_s"] == 1.10, "parts_missed"].round(1))
    chosen = sel[sel["verdict"] == "chosen"].iloc[0]
    m = re.search(r"\*\*trial (\d+)\*\* \(([\d.]+) in/s, ([\d.]+) s, ([\d.]+) parts/hr\)", text)
    assert m and int(m[1]) == chosen["trial"] and round(chosen["mean"], 1) == float(m[4])
    picked = trials[trials["trial"] == chosen["trial"]].iloc[0]
    assert (picked["belts.input_nominal_in_s"], picked["controller.nominal_cycle_s"]) == \
        (float(m[2]), float(m[3]))
    front_sel = sel[sel["trial"] == row["trial"]].iloc[0]
    assert front_sel["verdict"] == "eliminated"
    assert re.search(rf"costs about {chosen['mean'] - front_sel['mean']:.1f} parts/hr "
                     rf"\({front_sel['mean']:.1f}\)", text)


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
