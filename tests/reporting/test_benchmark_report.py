"""reports/benchmark/ (issue 36 item 4): the report is what today's code makes of its own runs,
its shares are the runs' counts over the optimum, every controller sits at or below the optimum
and the optimum at or below the MILP's bound and parts_bound, and the README quotes its
headline."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from cell.experiments import benchmark_runs as bm
from cell.reporting import benchmark as report

ROOT = Path(__file__).resolve().parents[2]
DIR = ROOT / "reports" / "benchmark"


@pytest.fixture(scope="module")
def runs() -> pd.DataFrame:
    return pd.read_csv(DIR / "runs.csv")


def test_the_report_is_what_the_code_makes_of_its_runs(runs: pd.DataFrame, tmp_path: Path,
                                                       unlaid: None) -> None:
    out = report.write(tmp_path / "b", runs.to_dict("records"))
    for name in ("report.md", "benchmark.csv", "runs.csv"):
        assert (out / name).read_bytes() == (DIR / name).read_bytes(), name


def test_every_run_sits_between_the_controllers_and_the_bounds(runs: pd.DataFrame) -> None:
    assert len(runs) == len(bm.POINTS) * bm.REPLICATIONS
    for c in bm.CONTROLLERS:
        assert (runs[c] <= runs["optimum"]).all(), c
    assert (runs["optimum"] >= runs["hindsight_search"]).all()
    assert (runs["optimum"] <= runs["milp_upper"]).all()
    assert (runs["milp_upper"] <= runs["parts_bound"]).all()
    assert (runs["parts_bound"] <= bm.PARTS).all()
    assert (runs["milp_status"] == "optimal").all()  # the bound proved in every run


def test_the_shares_are_the_counts_over_the_optimum(runs: pd.DataFrame) -> None:
    t = pd.read_csv(DIR / "benchmark.csv")
    for label, _, _ in bm.POINTS:
        r = runs[runs["point"] == label]
        row = t[(t["point"] == label) & (t["controller"] == report.SHOWN["adaptive"])].iloc[0]
        assert row["share"] == pytest.approx((r["adaptive"] / r["optimum"]).mean(), rel=1e-9)
        assert row["share_ci_low"] <= row["share"] <= row["share_ci_high"]


def test_the_readme_quotes_the_headline(runs: pd.DataFrame) -> None:
    line = report.headline(runs)
    assert line in (DIR / "report.md").read_text(encoding="utf-8")
    pct = f"{100 * runs['adaptive'].sum() / runs['optimum'].sum():.1f} %"
    assert pct in line
    readme = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    assert line in readme


def test_the_reading_gives_how_far_parts_bound_sits_above_the_optimum(runs: pd.DataFrame) -> None:
    """The reading's figures for parts_bound, worked from runs.csv: its pooled excess over the
    optimum and the runs where it meets the MILP's bound."""
    text = " ".join((DIR / "report.md").read_text(encoding="utf-8").split())
    above = 100 * (runs["parts_bound"].sum() / runs["optimum"].sum() - 1)
    met = int((runs["parts_bound"] == runs["milp_upper"]).sum())
    assert f"is {above:.1f} % above the optimum" in text
    assert f"meets the MILP's bound in {met} of the {len(runs)}" in text
