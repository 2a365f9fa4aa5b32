"""The layout study's reading (cell.reporting.maps.layout_study, ``make layout``): the places that
match the adaptive robot and where a second robot pays, read from the table as defined, on a
table made by hand; and the committed report is what its replications give."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from cell.reporting.maps import layout_study as layout

REPORT = Path(__file__).resolve().parents[2] / "reports" / "layout"


def _table(lost: dict[str, float], cv: float = 0.5) -> pd.DataFrame:
    return pd.DataFrame([{"cv": cv, "mean_s": 21.7009, "layout": name, "lost": value,
                          "spacing_kept": 1.0} for name, value in lost.items()])


def test_the_fewest_places_that_lose_no_more_than_the_adaptive_robot():
    lost = {"fixed, 0 places": 90.0, "fixed, 1 places": 50.0, "fixed, 2 places": 30.0,
            "fixed, 3 places": 20.0, "fixed, 5 places": 10.0, "adaptive, 0 places": 30.0,
            "adaptive, 1 places": 5.0, "two fixed robots": 12.0}
    m = layout.matches(_table(lost))
    assert m["places_to_match"].tolist() == [2]  # 30 <= 30: a tie matches
    assert m["two_lost"].tolist() == [12.0] and m["fixed5_lost"].tolist() == [10.0]
    worse = layout.matches(_table({**lost, "adaptive, 0 places": 5.0}))
    assert np.isnan(worse["places_to_match"].iloc[0])  # no number of places up to 5 does
    text = layout.headline(pd.concat([m, worse]))
    assert "2 places" in text and "at 1 of 2 arrival points" in text
    assert "adaptive robot at 1 of 2" in text and "5 places at 0 of 2" in text


def test_the_committed_report_is_its_replications_reading():
    t = pd.read_csv(REPORT / "layout.csv")
    m = layout.matches(t.assign(layout=t["layout"].astype(str)))
    assert layout.headline(m) in (REPORT / "README.md").read_text(encoding="utf-8")
    assert set(t["replications"]) == {20}
