"""The money reading (cell.reporting.money_reading): an option's cost is the run's sum
(cell.sim.run_cost) over its own counts, and the cheapest way to a loss target is the cheapest
option that meets it, whatever the options."""

from __future__ import annotations

import math

import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.reporting.money_reading import cheapest, priced, sentences, shares
from cell.scenario.energy_sections import CostSettings

COSTS = CostSettings.model_validate({"part_value": 12.0, "energy_per_kwh": 0.2, "downtime_per_h": 300,
                                     "repair": 150, "maintenance": 80})


def option(name: str, lost: float, good: float, hours: float = 3.0, down_h: float = 0.0,
           repairs: float = 0.0, options_per_h: float = 6.0) -> dict[str, object]:
    return {"option": name, "lost": lost, "good": good, "hours": hours, "down_h": down_h,
            "repairs": repairs, "maintenance": 1.0, "energy_kwh": 0.5, "options_per_h": options_per_h}


def test_an_options_cost_is_each_term_by_hand():
    t = priced(pd.DataFrame([option("a", lost=10, good=490, down_h=0.5, repairs=2)]), COSTS)
    hand = 10 * 12.0 + 0.5 * 0.2 + 0.5 * 300 + 2 * 150 + 1 * 80 + 6.0 * 3.0
    row = t.iloc[0]
    assert row["cost"] == pytest.approx(hand)
    assert row["cost_per_good_part"] == pytest.approx(hand / 490)
    assert row["cost_per_h"] == pytest.approx(hand / 3.0)
    assert sum(shares(row, COSTS).values()) == pytest.approx(1.0)
    assert shares(row, COSTS)["lost parts"] == pytest.approx(120 / hand)


def test_the_cheapest_way_to_a_target_may_cost_more_than_the_cheapest_overall():
    # b loses more and is cheaper per good part; only a meets a target of 1 part
    t = priced(pd.DataFrame([option("a", lost=0, good=100, options_per_h=400.0),
                             option("b", lost=5, good=100, options_per_h=6.0)]), COSTS)
    assert cheapest(t, 1.0)["option"] == "a"
    assert cheapest(t, math.inf)["option"] == "b"
    assert cheapest(t[t["option"] == "b"], 1.0) is None
    said = sentences(t, [1.0, math.inf], "option", "a run")
    assert len(said) == 2 and "a," in said[0] and "b," in said[1]


def test_targets_with_one_answer_are_said_once():
    t = priced(pd.DataFrame([option("a", lost=0, good=100), option("b", lost=3, good=97)]), COSTS)
    assert len(sentences(t, [1.0, 2.0], "option", "a run")) == 1   # a, and no other
    assert len(sentences(t, [1.0, 2.0, math.inf], "option", "a run")) == 2   # then b too


rows = st.lists(st.tuples(st.floats(0, 500), st.floats(0, 500), st.floats(0.1, 5000),
                          st.floats(0, 100), st.floats(0, 20)), min_size=1, max_size=8)


@settings(max_examples=60, deadline=None)
@given(rows, st.floats(0, 600))
def test_the_cheapest_meets_the_target_and_none_that_does_is_cheaper(rows, target):
    t = priced(pd.DataFrame([option(f"o{i}", lost=lost, good=good, hours=hours, down_h=down,
                                    options_per_h=opt) for i, (lost, good, hours, down, opt)
                             in enumerate(rows)]), COSTS)
    best = cheapest(t, target)
    meets = t[(t["lost"] <= target) & (t["good"] > 0)]
    if meets.empty:
        assert best is None
    else:
        assert best["lost"] <= target
        assert best["cost_per_good_part"] <= meets["cost_per_good_part"].min()
