"""``run.parts`` and ``run.hours``: a run's length is given one way; both given in one place is
refused whatever their values, and a layer above (``--set`` over a file, a file over the
defaults, a study's point over its base) that gives one replaces the other."""

from __future__ import annotations

from pathlib import Path

import pytest

from cell.plumbing.errors import ScenarioError
from cell.scenario.schema import load_scenario, validate


def test_both_given_are_refused_even_at_the_default_parts(tmp_path: Path) -> None:
    with pytest.raises(ScenarioError) as err:
        validate({"run": {"parts": 500, "hours": 1.0}}, "x.yaml")
    assert (err.value.key, err.value.value) == ("run.hours", 1.0)
    with pytest.raises(ScenarioError) as err:
        load_scenario("baseline", {"run.parts": 500, "run.hours": 1.0})
    assert err.value.key == "run.hours" and err.value.file.endswith("(--set)")


def test_a_layer_giving_one_length_replaces_the_other(tmp_path: Path) -> None:
    hours = load_scenario("baseline", {"run.hours": 2.0})  # baseline.yaml gives run.parts: 500
    assert hours.run.hours == 2.0 and "parts" not in hours.run.model_fields_set
    assert hours.with_overrides({}).run.hours == 2.0  # the round trip keeps it one way
    back = hours.with_overrides({"run.parts": 30})
    assert (back.run.parts, back.run.hours) == (30, None)
    file = tmp_path / "h.yaml"
    file.write_text("run: {hours: 0.5}\n", encoding="utf-8")
    assert load_scenario(file).run.hours == 0.5
    parts = load_scenario(file, {"run.parts": 5}).run
    assert (parts.parts, parts.hours) == (5, None)
    assert load_scenario(file, {"run": {"seed": 3}}).run.hours == 0.5  # a run key that is no length
