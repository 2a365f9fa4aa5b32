"""The ``energy:`` section: power per state of each piece of equipment, the run's energy as the
sum over states.csv of power times duration, and its bad inputs (one line naming the file, the
key and the value; exit 2; nothing written)."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import pytest
import yaml

from cell.cli.main import main


def run(*argv: str) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, err.getvalue()


@pytest.mark.parametrize(("energy", "key", "value"), [
    ({"power_w": {"robot": {"busy": -1.0}}}, "energy.power_w.robot.busy", "-1"),
    ({"power_w": {"input_belt": {"stopped": 3}}}, "energy.power_w.input_belt.stopped", "3"),
    ({"power_w": {"sensor": {"busy": 2}}}, "energy.power_w.sensor.busy", "2"),
    ({"power_w": {"robot": {"running": 2}}}, "energy.power_w.robot.running", "2"),
    ({"arm": "dynamics"}, "energy.arm", "dynamics"),
])
def test_bad_energy_input_names_file_key_and_value(tmp_path: Path, energy, key, value):
    scenario = {"energy": energy, "run": {"parts": 20}}
    if energy.get("arm") == "dynamics":  # no dynamic model to take the arm's energy from
        scenario["mintime"] = {"dynamics_file": None}
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(scenario))
    out = tmp_path / "out"
    code, err = run("run", str(path), "--out", str(out))
    assert code == 2
    line = err.strip()
    assert "\n" not in line and str(path) in line and key in line and value in line
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.parametrize("equipment", ["robot", "input_belt", "output_belt", "sensor"])
def test_every_equipment_takes_an_off_shift_power(tmp_path: Path, equipment):
    from cell.scenario.schema import load_scenario

    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump({"energy": {"power_w": {equipment: {"off_shift": 1.5}}}}))
    assert load_scenario(path).energy.power(equipment, "off_shift") == 1.5


def test_a_scenario_without_energy_reads_and_dumps_as_before():
    from cell.scenario.schema import default_scenario

    assert "energy" not in default_scenario().to_dict()
