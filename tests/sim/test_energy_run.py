"""The ``energy:`` section: power per state of each piece of equipment, the run's energy as the
sum over states.csv of power times duration, and its bad inputs (one line naming the file, the
key and the value; exit 2; nothing written)."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import pandas as pd
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


# --------------------------------------------------------------------------- state-based energy
POWER = {"robot": {"busy": 130.0, "waiting": 41.0, "idle": 37.0, "down": 6.0,
                   "maintenance": 9.0, "off_shift": 2.0},
         "input_belt": {"running": 55.0, "down": 1.0, "off_shift": 0.0},
         "output_belt": {"running": 65.0, "down": 2.0, "off_shift": 0.0},
         "sensor": {"up": 3.5, "down": 0.5, "off_shift": 0.0}}
FAILS = {"time_to_failure": {"distribution": "expon", "mean_h": 0.5},
         "time_to_repair": {"distribution": "expon", "mean_s": 300}}
SENSOR_FAILS = {**FAILS, "time_to_failure": {"distribution": "expon", "mean_h": 0.2},
                "clock": "calendar"}


@pytest.fixture(scope="module")
def failing_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A two-hour run with the robot, both belts and the sensor failing, and maintenance."""
    return _failing(tmp_path_factory.mktemp("energy"), {"energy": {"power_w": POWER}}, {})


def _failing(where: Path, more: dict, robot: dict) -> Path:
    """``cell run`` of two hours with the robot (``robot``: more of its keys), both belts and
    the sensor failing, and maintenance, plus the sections ``more``; its output folder."""
    scenario = {"run": {"hours": 2.0}, "sensor": {"lookahead": "sensor"}, **more,
                "failures": {"robot": {**FAILS, "clock": "calendar", **robot},
                             "input_belt": FAILS, "output_belt": FAILS, "sensor": SENSOR_FAILS,
                             "maintenance": {"every_h": 0.75, "duration_min": 10}}}
    path = where / "scenario.yaml"
    path.write_text(yaml.safe_dump(scenario))
    code, err = run("run", str(path), "--out", str(where / "out"))
    assert code == 0, err
    return where / "out"


def test_state_based_energy_is_the_sum_over_states_csv_of_power_times_duration(failing_run):
    states = pd.read_csv(failing_run / "states.csv")
    summary = pd.read_csv(failing_run / "summary.csv").iloc[0]
    # the run visits the states whose power it is meant to count
    seen = set(zip(states.equipment, states.state))
    assert {("robot", "down"), ("robot", "maintenance"), ("robot", "busy"),
            ("input_belt", "down"), ("output_belt", "down"), ("sensor", "down")} <= seen
    joules = sum(POWER[e][s] * (b - a)
                 for e, s, a, b in zip(states.equipment, states.state, states.from_s, states.to_s))
    assert summary.energy_kwh * 3.6e6 == pytest.approx(joules, rel=1e-9)
    parts = pd.read_csv(failing_run / "parts.csv")
    good = int(parts.touchdown_s.notna().sum())  # quality.rule set_down: every part set down
    assert summary.energy_per_good_part_wh == pytest.approx(joules / 3600 / good, rel=1e-9)


def test_each_equipments_states_tile_the_run(failing_run):
    states = pd.read_csv(failing_run / "states.csv")
    end = pd.read_csv(failing_run / "summary.csv").sim_end_s.iloc[0]
    assert set(states.equipment) == set(POWER)
    for _, rows in states.groupby("equipment"):
        assert rows.from_s.iloc[0] == 0.0 and rows.to_s.iloc[-1] == pytest.approx(end)
        assert (rows.from_s.to_numpy()[1:] == rows.to_s.to_numpy()[:-1]).all()


def test_without_energy_the_summary_has_its_columns_and_no_states_csv(tmp_path: Path):
    from cell.sim.records import SUMMARY_COLUMNS

    base = ("run", "baseline", "--set", "run.parts=40")
    assert run(*base, "--out", str(tmp_path / "b"))[0] == 0
    assert run(*base, "--set", "energy={arm: none}", "--out", str(tmp_path / "e"))[0] == 0
    assert not (tmp_path / "b" / "states.csv").exists() and (tmp_path / "e" / "states.csv").exists()
    plain = pd.read_csv(tmp_path / "b" / "summary.csv")
    energy = pd.read_csv(tmp_path / "e" / "summary.csv")
    assert list(plain.columns) == SUMMARY_COLUMNS
    assert list(energy.columns) == [*SUMMARY_COLUMNS, "energy_kwh", "energy_per_good_part_wh"]
    # the energy section measures; it does not change the run
    pd.testing.assert_frame_equal(plain, energy[SUMMARY_COLUMNS])


# --------------------------------------------------------------------------- the arm's own energy
@pytest.fixture(scope="module")
def arm_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A run with the arm's motion energy from its dynamic model, the robot failing."""
    where = tmp_path_factory.mktemp("arm")
    code, err = run("run", "baseline", "--set", "run.parts=120", "--set",
                    f"energy={yaml.safe_dump({'power_w': POWER, 'arm': 'dynamics'}, width=1e9)}",
                    "--set", f"failures={yaml.safe_dump({'robot': FAILS}, width=1e9)}",
                    "--out", str(where))
    assert code == 0, err
    return where


def test_with_arm_dynamics_the_arms_energy_replaces_the_busy_power(arm_run):
    """The run's energy: every state's power × duration but the robot's busy rows, plus each
    picked part's transfer energy (energy_j), all read from the run's own files."""
    from cell.sim.records import PART_COLUMNS

    states = pd.read_csv(arm_run / "states.csv")
    parts = pd.read_csv(arm_run / "parts.csv")
    summary = pd.read_csv(arm_run / "summary.csv").iloc[0]
    assert list(parts.columns) == [*PART_COLUMNS, "energy_j"]
    assert parts.energy_j[parts.picked].notna().all() and parts.energy_j[~parts.picked].isna().all()
    flat = sum(POWER[e][s] * (b - a) for e, s, a, b in
               zip(states.equipment, states.state, states.from_s, states.to_s)
               if (e, s) != ("robot", "busy"))
    assert summary.energy_kwh * 3.6e6 == pytest.approx(flat + parts.energy_j.sum(), rel=1e-9)
    # the summary's energy per transfer is parts.csv's, averaged over the transfers costed
    assert summary.arm_energy_per_transfer_j == pytest.approx(parts.energy_j.mean(), rel=1e-9)


def test_a_transfer_costs_at_least_the_drives_standing_draw_over_its_time(arm_run):
    from cell.scenario.catalog import BUILT_IN
    from cell.scenario.dynamics_file import load_dynamics

    standing_w = load_dynamics(BUILT_IN / "microbot_dynamics.yaml").electrical.standing_w().sum()
    parts = pd.read_csv(arm_run / "parts.csv")
    picked = parts[parts.picked]
    motion_s = picked[["r1_s", "r2_s", "r3_s", "r4_s"]].sum(axis=1)
    extra = picked.energy_j - standing_w * motion_s  # the motion's own work, over the drives'
    assert (extra > 0).all() and (extra < 0.05 * picked.energy_j).all()


# --------------------------------------------------------------------------- costs
COSTS = {"part_value": 12.0, "energy_per_kwh": 0.2, "downtime_per_h": 300.0, "repair": 150.0,
         "maintenance": 80.0, "options_per_h": {"sensor": 0.4, "buffer_place": 0.1, "robot": 6.0,
                                                "adaptive_controller": 0.5}}


@pytest.fixture(scope="module")
def costed_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The failing run of :func:`failing_run`, with costs and the spacing quality rule."""
    return _failing(tmp_path_factory.mktemp("costs"),
                    {"quality": {"rule": "spacing"}, "energy": {"power_w": POWER}, "costs": COSTS},
                    {"part_in_hand": "scrap"})


def test_the_cost_is_the_hand_computation_from_the_runs_files(costed_run):
    parts = pd.read_csv(costed_run / "parts.csv", keep_default_na=False, na_values=[""])
    states = pd.read_csv(costed_run / "states.csv")
    stops = pd.read_csv(costed_run / "failures.csv")
    summary = pd.read_csv(costed_run / "summary.csv").iloc[0]
    hours = summary.sim_end_s / 3600
    limits = parts.limits.fillna("").str.split()
    scrapped = limits.map(lambda names: "scrapped" in names)
    lost = int(parts.missed.sum()) + int(scrapped.sum())
    assert scrapped.any() and parts.missed.any()
    down = states[(states.equipment == "robot") & (states.state == "down")]
    down_h = float((down.to_s - down.from_s).sum()) / 3600
    maintenance = int((stops.cause == "maintenance").sum())
    repairs = len(stops) - maintenance
    assert maintenance > 0 and repairs > 0
    options = 6.0 + 0.4 + 0.5  # one robot, the sensor (lookahead: sensor), the adaptive controller
    cost = (lost * 12.0 + summary.energy_kwh * 0.2 + down_h * 300.0 + repairs * 150.0
            + maintenance * 80.0 + options * hours)
    off_spacing = limits.map(lambda names: "spacing_off" in names)
    good = int((parts.touchdown_s.notna() & ~off_spacing).sum())  # quality.rule: spacing
    assert summary.cost_per_h == pytest.approx(cost / hours, rel=1e-9)
    assert summary.cost_per_good_part == pytest.approx(cost / good, rel=1e-9)


@pytest.mark.parametrize(("key", "value"), [
    ("costs.part_value", -1), ("costs.energy_per_kwh", -0.2),
    ("costs.options_per_h.sensor", -0.4), ("costs.options_per_h.conveyor", 1.0)])
def test_bad_costs_name_file_key_and_value(tmp_path: Path, key, value):
    section: dict = {}
    where = section
    *path, last = key.split(".")[1:]
    for name in path:
        where = where.setdefault(name, {})
    where[last] = value
    scenario_file = tmp_path / "bad.yaml"
    scenario_file.write_text(yaml.safe_dump({"costs": section, "run": {"parts": 20}}))
    code, err = run("run", str(scenario_file), "--out", str(tmp_path / "out"))
    line = err.strip()
    assert code == 2 and "\n" not in line
    assert str(scenario_file) in line and key in line and str(value) in line
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
