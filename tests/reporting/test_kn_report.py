"""reports/kn (``make kn-check``) is what today's KN gives, and shows what issue 35 asks: KN's
probability of correct selection on a count with a first stage of 2 or 3, over at least
1,000 problems, at or above its nominal level minus its own standard error, or the
selection refused."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from cell.reporting.formatting import table_row
from cell.reporting.kn_report import COLUMNS, MACRO, PCS, holds, poisson_rows

REPORT = Path(__file__).resolve().parents[2] / "reports" / "kn"


@pytest.fixture(scope="module")
def committed() -> pd.DataFrame:
    return pd.read_csv(REPORT / "pcs.csv")


def test_the_small_first_stage_on_a_count_holds_its_probability(committed) -> None:
    ruled = committed[committed["rule"] == "with"]
    small = ruled[ruled["n0"].isin([2, 3])]
    assert {"simulated, CRN", "simulated, independent", "Poisson"} <= set(small["case"])
    assert (small["macro"] >= 1000).all()
    for row in ruled.itertuples():
        assert row.refused + row.unfinished + row.decided == row.macro
        assert row.decided == 0 or row.pcs >= PCS - row.se, row


def test_the_rows_say_what_their_counts_give(committed) -> None:
    for row in committed.itertuples():
        pcs = row.correct / row.decided
        se = (pcs * (1 - pcs) / row.decided) ** 0.5
        assert row.pcs == pytest.approx(pcs, abs=5e-5) and row.se == pytest.approx(se, abs=5e-5)
        assert row.holds == holds(row.pcs, row.se)


def test_the_committed_rows_are_todays_code(committed) -> None:
    """The Poisson rows at n0 = 10, recomputed (pure numpy, a second): the same counts."""
    fresh = pd.DataFrame(list(poisson_rows((10,))), columns=COLUMNS)
    old = committed[(committed["case"] == "Poisson") & (committed["n0"] == 10)]
    assert len(fresh) == 2 and (fresh["macro"] == MACRO).all()
    cols = ["rule", "refused", "unfinished", "decided", "correct"]
    assert fresh[cols].reset_index(drop=True).equals(old[cols].reset_index(drop=True))


def test_the_readme_shows_the_csv(committed) -> None:
    text = (REPORT / "README.md").read_text(encoding="utf-8")
    for row in committed[COLUMNS].itertuples(index=False):
        assert table_row(str(v) for v in row) in text
