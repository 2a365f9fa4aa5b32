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


def test_the_committed_money_follows_from_its_own_csv():
    """layout.csv's money is its own counts at scenarios/layout_study.yaml's prices: the parts
    lost, and the hours at the options each layout has (each robot with its sensor, a place
    of buffer each, the adaptive controller for the adaptive robot); the README names the
    cheapest layout per arrival point and loss target."""
    import yaml

    prices = yaml.safe_load((REPORT.parents[1] / "scenarios" / "layout_study.yaml")
                            .read_text(encoding="utf-8"))["set"]
    t = pd.read_csv(REPORT / "layout.csv")
    name = t["layout"].astype(str)
    robots = np.where(name == "two fixed robots", 2, 1)
    places = name.str.extract(r"(\d+) places")[0].fillna("0").astype(int)
    options = (robots * (prices["costs.options_per_h.robot"]
                         + prices["costs.options_per_h.sensor"])
               + places * prices["costs.options_per_h.buffer_place"]
               + name.str.startswith("adaptive") * prices["costs.options_per_h.adaptive_controller"])
    assert np.allclose(t["options_per_h"], options, rtol=1e-12)
    hand = (t["lost"] * prices["costs.part_value"] + t["down_h"] * prices["costs.downtime_per_h"]
            + t["repairs"] * prices["costs.repair"] + options * t["hours"])
    assert (t["down_h"] == 0).all() and (t["repairs"] == 0).all()  # the study has no failures
    assert np.allclose(hand, t["cost"], rtol=1e-9)
    assert np.allclose(t["cost"] / t["good"], t["cost_per_good_part"], rtol=1e-9)
    assert np.allclose(t["good"] + t["lost"], 500)  # every part delivered or lost
    text = (REPORT / "README.md").read_text(encoding="utf-8")
    for (cv, mean), point in t.groupby(["cv", "mean_s"]):
        at = text.index(f"**cv {cv:g}, load {mean / layout.FASTEST_S:.2f}.**")
        paragraph = text[at:text.index("\n", at)]
        for target in layout.LOSS_TARGETS:
            meets = point[point["lost"] <= target]
            if len(meets):
                best = meets.loc[meets["cost_per_good_part"].idxmin()]
                assert f"cheapest with {best['layout']}, {best['cost_per_good_part']:.4f}" \
                    in paragraph
