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
