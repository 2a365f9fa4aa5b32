"""The reliability study's report (cell.reporting.maps.reliability; reports/reliability/)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cell.reporting.maps import reliability as rel
from tests.prose import in_order

ROOT = Path(__file__).resolve().parents[2]
REPORT = ROOT / "reports" / "reliability"


def _table(mtbf_fixed: dict[float, float], mtbf_adaptive: float = 1000.0) -> pd.DataFrame:
    """A made-up study table: the fixed robot's MTBF at its shortest cycle per exponent."""
    rows = []
    for p, short in mtbf_fixed.items():
        for policy, cycle, mtbf in (("non-adaptive", 22.5872, 1500.0),
                                    ("non-adaptive", 20.0907, short),
                                    ("adaptive", np.nan, mtbf_adaptive)):
            down = 4.0 * rel.YEAR_H / (mtbf + 4.0)
            rows.append({"wear_exponent": p, "policy": policy, "cycle_s": cycle,
                         "robot_mtbf_h": mtbf, "expected_down_h_per_year": down,
                         "parts_per_h": 150.0 if policy == "adaptive" else 140.0,
                         "oee": 0.9})
    return pd.DataFrame(rows)


def test_the_verdict_and_where_it_flips() -> None:
    """log(MTBF ratio) −0.1 at p = 1 and +0.1 at p = 2 (ratio e^±0.1) crosses 0 at p = 1.5."""
    t = _table({0.0: 1000 * np.exp(0.3), 1.0: 1000 * np.exp(0.1), 2.0: 1000 * np.exp(-0.1),
                3.0: 1000 * np.exp(-0.3)})
    v = rel.verdicts(t)
    assert v["holds"].tolist() == [False, False, True, True]
    assert v["mtbf_ratio"].iloc[3] == pytest.approx(np.exp(-0.3))
    assert rel.flip_exponent(v) == pytest.approx(1.5)
    text = rel.headline(t)
    held = ", ".join(f"{p:g}" for p in v.loc[v["holds"], "wear_exponent"])  # 2, 3 (above)
    assert in_order(text, f"exponents {held}", f"p ≈ {rel.flip_exponent(v):.2f}")
    assert f"{100 * (1 - np.exp(-0.3)):.0f} % shorter" in text


def test_no_flip_when_the_fixed_robot_always_wears_faster() -> None:
    t = _table({0.0: 900.0, 3.0: 500.0})
    assert rel.flip_exponent(rel.verdicts(t)) is None
    assert "holds for every exponent swept:" in rel.headline(t)


def test_the_committed_report_says_what_its_numbers_say() -> None:
    """README.md's headline and reading are those of reliability.csv, the table it was made from
    (the repository's README quotes its figures: tests/reporting/test_readme.py)."""
    t = pd.read_csv(REPORT / "reliability.csv")
    assert set(t["wear_exponent"]) >= {0.0, 1.0}  # the exponent swept, 0 included
    assert set(t["cycle_s"].dropna()) == {22.5872, 22.0, 21.5, 21.0, 20.5, 20.0907}
    text = (REPORT / "README.md").read_text(encoding="utf-8")
    for sentence in rel.reading(t):
        assert sentence in text
    assert (REPORT / "reliability.png").stat().st_size > 10_000


def test_the_committed_robot_mtbf_is_the_renewal_figure_of_its_motor_lives() -> None:
    """Only the worn motor is replaced, so the robot's mean time between wear stops is
    1 / Σ_j 1 / (η_j Γ(1 + 1/β)) over the motor lives the report gives (each a mean over the
    replications, whose duties differ by a few missed parts), not the mean life of five fresh
    motors in series; the expected downtime is the alternating renewal figure from it."""
    from cell.experiments.sweep.spec import load_sweep

    wear = load_sweep(ROOT / "scenarios" / "reliability.yaml").base.wear
    t = pd.read_csv(REPORT / "reliability.csv")
    lives = t[[f"wear_life_{j}_h" for j in ("base", "shoulder", "elbow", "pitch", "roll")]]
    renewal = math.gamma(1 + 1 / wear.shape) / (1 / lives).sum(axis=1)
    assert np.allclose(t["robot_mtbf_h"], renewal, rtol=1e-3)
    down = wear.repair_h / (t["robot_mtbf_h"] + wear.repair_h) * rel.YEAR_H
    assert np.allclose(t["expected_down_h_per_year"], down, rtol=1e-3)


def test_the_committed_money_follows_from_its_own_csv() -> None:
    """reliability.csv's money is its own year's counts at scenarios/reliability.yaml's prices:
    lost parts, the robot's downtime as run, its wear stops, and the hours at the options each
    robot has (the adaptive controller only for the adaptive one); lost and good parts agree
    with the table's own per-year figures; the README names the cheapest option per target."""
    import yaml

    prices = yaml.safe_load((ROOT / "scenarios" / "reliability.yaml").read_text())["set"]
    t = pd.read_csv(REPORT / "reliability.csv")
    assert (t["hours"] == rel.YEAR_H).all()
    hand = (t["lost"] * prices["costs.part_value"] + t["down_h"] * prices["costs.downtime_per_h"]
            + t["repairs"] * prices["costs.repair"]
            + (prices["costs.options_per_h.robot"] + (t["policy"] == rel.ADAPTIVE)
               * prices["costs.options_per_h.adaptive_controller"]) * rel.YEAR_H)
    assert np.allclose(hand, t["cost"], rtol=1e-9)
    assert np.allclose(t["cost"] / t["good"], t["cost_per_good_part"], rtol=1e-9)
    # the same year as the table's: its downtime as run, its wear stops, its parts (the table
    # averages each run's rate, the money the runs' totals: equal to the runs' spread in hours)
    assert np.allclose(t["down_h"], t["down_h_per_year"], rtol=1e-3)
    assert np.allclose(t["repairs"], t["stops_per_year"], rtol=1e-3)
    assert np.allclose(t["good"], t["parts_per_h"] * rel.YEAR_H, rtol=1e-3)
    assert (t["lost"] >= t["parts_missed_per_year"] * 0.99).all()
    text = (REPORT / "README.md").read_text(encoding="utf-8")
    for _, options in t.groupby("wear_exponent"):
        for target in rel.LOSS_TARGETS:
            meets = options[options["lost"] <= target]
            if len(meets):
                best = meets.loc[meets["cost_per_good_part"].idxmin()]
                assert f"cheapest with {rel.option_name(best)}, {best['cost_per_good_part']:.4f}" in text
