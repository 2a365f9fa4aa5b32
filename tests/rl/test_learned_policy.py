"""The learned controller is a plug-in policy like any other: cell run, cell compare, cell sweep
and the stress map take it by name; with a zero network it is the thesis's adaptive decision,
and running it needs no training library."""

from __future__ import annotations

import csv
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cell.cli.main import main
from cell.rl.learned import Learned, load_weights, size
from cell.scenario.schema import load_scenario
from cell.sim.assembly import AssembledCell, assemble
from cell.sim.simulation import simulate

STRESSED = {"arrivals.distribution": "gamma", "arrivals.cv": 1.0, "arrivals.mean_s": 17.1799,
            "controller.nominal_cycle_s": None, "sensor.lookahead": "sensor", "run.parts": 80}


def test_a_zero_network_is_the_adaptive_decision() -> None:
    s = load_scenario("baseline", {**STRESSED, "controller.policy": "adaptive"})
    cell = assemble(s)
    zero = AssembledCell(s, cell.timing, cell.k, Learned(cell.k, s.controller, None,
                                                         np.zeros(size())))
    a, b = simulate(cell, seed=3).records, simulate(zero, seed=3).records
    assert [repr(r) for r in a] == [repr(r) for r in b]


def test_the_committed_weights_change_the_decisions() -> None:
    assert load_weights().shape == (size(),) and np.abs(load_weights()).max() > 0
    s = load_scenario("baseline", STRESSED)
    learned = simulate(s.with_overrides({"controller.policy": "learned"}), seed=3).records
    adaptive = simulate(s.with_overrides({"controller.policy": "adaptive"}), seed=3).records
    assert [r.input_speed_in_s for r in learned] != [r.input_speed_in_s for r in adaptive]


def test_cell_run_takes_it_without_a_training_library(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    for library in ("cma", "torch"):  # an import of either now fails
        monkeypatch.setitem(sys.modules, library, None)
    assert main(["run", "baseline", "--out", str(tmp_path / "r"), "--set",
                 "controller.policy=learned", "--set", "run.parts=30"]) == 0
    with open(tmp_path / "r" / "summary.csv", newline="") as f:
        assert next(csv.DictReader(f))["policy"] == "learned"


@pytest.mark.usefixtures("unlaid")
def test_cell_compare_takes_it(tmp_path: Path) -> None:
    a, b = tmp_path / "learned.yaml", tmp_path / "adaptive.yaml"
    for path, policy in ((a, "learned"), (b, "adaptive")):
        path.write_text(f"name: {policy}\ncontroller:\n  policy: {policy}\nrun:\n  parts: 40\n")
    assert main(["compare", str(a), str(b), "--replications", "3", "--workers", "1",
                 "--out", str(tmp_path / "c")]) == 0
    reps = pd.read_csv(tmp_path / "c" / "replications.csv")
    assert set(reps["policy"]) == {"learned", "adaptive"}


@pytest.mark.usefixtures("unlaid")
def test_a_sweep_and_the_stress_map_take_it(tmp_path: Path) -> None:
    from cell.reporting.maps import stress

    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(
        "name: tiny\nbase: baseline\nset:\n  run.parts: 40\n  controller.nominal_cycle_s: null\n"
        "  sensor.lookahead: sensor\ngrid:\n  arrivals.distribution: [gamma]\n"
        "  arrivals.cv: [1.0]\n  arrivals.mean_s: [17.1799]\n"
        "policies: [non-adaptive, adaptive, learned]\nreplications: 3\nseed: 1984\n")
    assert main(["sweep", str(sweep), "--out", str(tmp_path / "s"), "--workers", "1"]) == 0
    stress.write(tmp_path / "s" / "replications.csv", tmp_path / "map")
    table = pd.read_csv(tmp_path / "map" / "stress.csv")
    assert list(table["policy"]) == ["non-adaptive", "adaptive", "learned"]


def test_docs_quote_the_committed_training_scores() -> None:
    import json

    from cell.rl.learned import WEIGHTS

    found = json.loads(WEIGHTS.read_text(encoding="utf-8"))
    assert found["parts_delivered"] > found["parts_delivered_adaptive"]
    docs = Path(__file__).resolve().parents[2] / "docs" / "rl.md"
    text = " ".join(docs.read_text(encoding="utf-8").split())
    assert f"({found['parts_delivered']} parts against {found['parts_delivered_adaptive']})" in text
