"""docs/model.md's "Departures from the thesis's controller": how often each addition binds on
the thesis's arrivals is what the committed Table 7.1 sweep counts (reports/table_7_1/summary.csv,
adaptive robot), rounded to the digits printed."""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd
import pytest

from tests.readme_sources import agrees, phrase, prose

ROOT = Path(__file__).resolve().parents[2]
MODEL = (ROOT / "docs" / "model.md").read_text(encoding="utf-8")
SUMMARY = ROOT / "reports" / "table_7_1" / "summary.csv"


@pytest.fixture(scope="module")
def adaptive() -> pd.DataFrame:
    frame = pd.read_csv(SUMMARY)
    return frame[(frame.policy == "adaptive")
                 & ((frame["controller.ideal_cycle_s"] - 22.5872).abs() < 1e-9)].set_index("measure")


def column() -> dict[str, str]:
    """The departures table: each addition's right-hand cell."""
    start = MODEL.index("| addition | rule |")
    rows = MODEL[start:MODEL.index("\n\n", start)].splitlines()[2:]
    return {cells[1].strip(): cells[-2].strip() for cells in (r.split("|") for r in rows)}


def n_times(adaptive: pd.DataFrame, measure: str) -> float:
    """A per-run mean back to the count over all runs."""
    return float(adaptive.loc[measure, "mean"] * adaptive.loc[measure, "n"])


def test_the_table_says_where_its_numbers_come_from(adaptive: pd.DataFrame) -> None:
    head = phrase("on the thesis's arrivals (adaptive, {} runs of {} parts)").search(MODEL)
    assert head is not None
    assert int(head[1]) == adaptive.loc["parts_arrived", "n"]
    assert float(head[2]) == adaptive.loc["parts_arrived", "mean"]
    assert "reports/table_7_1/summary.csv" in MODEL


@pytest.mark.parametrize(("addition", "template", "measure"), [
    ("input belt ceiling", "{} parts a run", "limit_input_ceiling"),
    ("robot tracking limit", "{} parts a run", "limit_input_tracking"),
    ("R II and R IV at their peaks", "R IV: {} parts a run", "limit_r4_peak"),
])
def test_a_limit_that_binds_is_its_mean_per_run(adaptive: pd.DataFrame, addition: str,
                                                template: str, measure: str) -> None:
    cell = phrase(template).search(column()[addition])
    assert cell is not None, column()[addition]
    assert agrees(cell[1], float(adaptive.loc[measure, "mean"]))
    assert adaptive.loc[measure, "mean"] > 0


def test_the_output_floor_never_binds_under_the_spacing_contract(adaptive: pd.DataFrame) -> None:
    """With the output belt steered over the whole interval between touch-downs, Table 7.1's
    adaptive runs never leave it at its floor or ceiling, and no part lands off spacing; the
    table and the prose say so (before the contract: 3 parts in 200 runs)."""
    cell = column()["output belt floor and ceiling"]
    assert "with the spacing contract: never" in cell and "ceiling never" in cell
    for measure in ("limit_output_floor", "limit_output_ceiling", "spacing_outside_tol"):
        assert n_times(adaptive, measure) == 0, measure
    assert "the output belt's floor (with the spacing contract)" in prose(MODEL)


@pytest.mark.parametrize(("addition", "measures"), [
    ("input belt floor", ["limit_input_floor"]),
    ("R II and R IV at their peaks", ["limit_r2_peak"]),
    ("solid parts", ["parts_held", "feed_delay_max_s"]),
])
def test_never_is_zero_in_every_run(adaptive: pd.DataFrame, addition: str,
                                    measures: list[str]) -> None:
    assert re.search(r"\bnever\b", column()[addition])
    for measure in measures:   # counts and maxima: a mean of 0 is 0 in every run
        assert adaptive.loc[measure, "mean"] == 0, measure
