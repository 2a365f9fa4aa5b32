"""The README's sweep file runs as written (stand-in replications: 200 of them at 8 points)."""

from __future__ import annotations

import re

import pandas as pd

from cell.cli.main import main
from cell.experiments.sweep import load_sweep
from tests.reporting.test_readme import section


def readme_sweep() -> str:
    """The first YAML block of the README's section on experiments."""
    found = re.search(r"```yaml\n(.*?)```", section("## Experiments"), re.S)
    assert found, "no sweep file in the README's Experiments section"
    return found.group(1)


def test_the_readme_sweep_runs_as_written_against_its_baseline(tmp_path, capsys, monkeypatch,
                                                                sweeps):
    """Every point but the baseline's is compared with the non-adaptive robot at 22.5872 s at
    its own output belt speed: the adaptive robot and the two shorter cycles."""
    monkeypatch.setattr("cell.experiments.sweep.simulate_summary", sweeps.bookkeeping)
    path = tmp_path / "readme_sweep.yaml"
    path.write_text(readme_sweep(), encoding="utf-8")
    code = main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1"])
    assert code == 0, capsys.readouterr().err
    assert len(pd.read_csv(tmp_path / "o" / "replications.csv")) == 8 * 200
    sweep = load_sweep(path)
    pairs = [(sweep.points[p.point], sweep.points[p.versus]) for p in sweep.pairs()]
    belt = "belts.output_nominal_in_s"
    assert sorted((a.policy, dict(a.values).get("controller.ideal_cycle_s", 0),
                   dict(a.values)[belt]) for a, _ in pairs) == [
        ("adaptive", 0, 2.0), ("adaptive", 0, 2.5),
        ("non-adaptive", 21.5, 2.0), ("non-adaptive", 21.5, 2.5),
        ("non-adaptive", 22.0, 2.0), ("non-adaptive", 22.0, 2.5)]
    for a, b in pairs:
        assert (b.policy, dict(b.values)) == (
            "non-adaptive", {belt: dict(a.values)[belt], "controller.ideal_cycle_s": 22.5872})
