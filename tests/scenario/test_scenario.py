"""Scenario files: defaults, overrides, and one clear line for every bad input."""


import numpy as np
import pytest
import yaml

from cell.plumbing.errors import ScenarioError
from cell.scenario import catalog
from cell.scenario.schema import WEIBULL_SHAPE, default_scenario, known_key, load_scenario, validate
from cell.sim.physics_checks import step_table
from tests.prose import error_parts


def from_dict(raw, file="<dict>"):
    return validate(raw, file)


def to_dict(s):
    return s.to_dict()

#: Where baseline.yaml and the built-in defaults differ: baseline states the thesis's quoted
#: ideal cycle; the built-in default follows the arrivals' own mean (22.586 s for eq. 6.9).
#: (The planner's settings agree: a small file under minimum-time timing plans as baseline.)
MODEL_SWITCH = {("controller", "nominal_cycle_s"): (22.5872, None)}


def test_baseline_yaml_is_the_thesis_defaults():
    """scenarios/baseline.yaml spells out every default: file and code cannot drift apart."""
    base = to_dict(load_scenario(catalog.path("baseline")))
    defaults = to_dict(default_scenario())
    for (section, key), (in_file, default) in MODEL_SWITCH.items():
        assert (base[section].pop(key), defaults[section].pop(key)) == (in_file, default)
    for name in ("name", "description"):
        base.pop(name), defaults.pop(name)
    for section in base:
        assert _close(base[section], defaults[section]), section


def _close(a, b):
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_close(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(_close(x, y) for x, y in zip(a, b))
    if isinstance(a, float):
        return abs(a - b) <= 1e-9 * max(1, abs(b))
    return a == b


def test_weibull_shape_is_eq_6_9():
    assert WEIBULL_SHAPE == pytest.approx(4.9068, abs=1e-4)
    assert default_scenario().arrivals.params["c"] == WEIBULL_SHAPE


def test_overrides_are_validated():
    s = default_scenario().with_overrides({"run.parts": 10, "belts.input_nominal_in_s": 2.5})
    assert s.run.parts == 10 and s.belts.input_nominal_in_s == 2.5
    with pytest.raises(ScenarioError, match=r"run\.parts = 0: must be at least 1"):
        default_scenario().with_overrides({"run.parts": 0})


def test_an_error_in_a_set_value_says_it_came_from_set(tmp_path):
    """A bad --set value is not the file's fault: the line says where it came from."""
    path = tmp_path / "mine.yaml"
    path.write_text("run: {parts: 0}\n")
    with pytest.raises(ScenarioError) as from_file:
        load_scenario(path)
    assert "(--set)" not in str(from_file.value)
    for sets, key in [({"run.parts": 0}, "run.parts"), ({"run": {"parts": 0}}, "run.parts"),
                      ({"arrivals.params.scale": -1.0}, "arrivals.params"),
                      ({"robot.motors.steps_per_rad": [1125, 1125, 0.5, 241, 241]},
                       "robot.motors.steps_per_rad[2]")]:
        with pytest.raises(ScenarioError) as err:
            load_scenario("baseline", sets)
        assert err.value.key == key and "baseline.yaml (--set)" in str(err.value)
    with pytest.raises(ScenarioError) as other:  # a --set that is fine; the file's value is not
        load_scenario(path, {"run.seed": 3})
    assert "(--set)" not in str(other.value)


def test_a_physics_error_from_a_set_value_also_says_so(tmp_path, capsys):
    """Found when the cell is assembled, after loading: still the command line's value."""
    from cell.cli.main import main

    code = main(["run", "baseline", "--set", "belts.input_nominal_in_s=1000", "--set",
                 "belts.input_max_in_s=1000", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    line = error_parts(err.strip())
    assert code == 2 and (line.key, line.value) == ("belts.input_nominal_in_s", "1000.0")
    assert line.file.endswith("baseline.yaml (--set)")
    assert not (tmp_path / "o").exists()


def test_a_file_named_by_set_is_found_from_the_working_directory(tmp_path, monkeypatch):
    """``--set arrivals.trace_csv=log.csv`` names ./log.csv, whatever folder the scenario is in
    (a built-in one's is inside the package); the scenario file's own paths stay its own."""
    (tmp_path / "log.csv").write_text("interarrival_s\n20\n25\n")
    monkeypatch.chdir(tmp_path)
    s = load_scenario("baseline", {"arrivals.trace_csv": "log.csv"})
    assert s.base_dir / s.arrivals.trace_csv == tmp_path / "log.csv"
    s = load_scenario("baseline", {"arrivals": {"trace_csv": "log.csv"}})  # a section given whole
    assert s.base_dir / s.arrivals.trace_csv == tmp_path / "log.csv"
    own = tmp_path / "sub"
    own.mkdir()
    (own / "own.csv").write_text("interarrival_s\n21\n")
    (own / "s.yaml").write_text("arrivals: {trace_csv: own.csv}\n")
    s = load_scenario(own / "s.yaml", {"run.parts": 3})
    assert s.base_dir / s.arrivals.trace_csv == own / "own.csv"
    s = load_scenario(own / "s.yaml", {"arrivals": {"distribution": "expon"}})  # not named
    assert s.base_dir / s.arrivals.trace_csv == own / "own.csv"
    (own / "log.csv").write_text("interarrival_s\n22\n")  # the file's folder has one too
    (own / "s.yaml").write_text("arrivals: {trace_csv: log.csv}\n")
    for sets in ({"arrivals.trace_csv": "log.csv"}, {"arrivals": {"trace_csv": "log.csv"}}):
        s = load_scenario(own / "s.yaml", sets)  # the same name as the file's, but from --set
        assert s.base_dir / s.arrivals.trace_csv == tmp_path / "log.csv"


def test_known_key():
    assert known_key("controller.ideal_cycle_s")
    assert known_key("robot.motors.nominal_fraction")
    assert not known_key("controller.cycle")
    assert not known_key("run.parts.x")
    assert not known_key("source")


BAD = [
    ({"pth": 1}, "pth", "unknown key"),
    ({"robot": {"motors": {"stepz_per_rad": 1}}}, "robot.motors.stepz_per_rad", "unknown key"),
    ({"run": {"parts": "many"}}, "run.parts", "whole number"),
    ({"run": {"parts": 2.5}}, "run.parts", "whole number"),
    ({"run": {"parts": 0}}, "run.parts", "at least 1"),
    ({"run": {"parts": -5}}, "run.parts", "at least 1"),
    ({"belts": {"input_nominal_in_s": -3.0}}, "belts.input_nominal_in_s", "greater than 0"),
    ({"belts": {"output_nominal_in_s": 0}}, "belts.output_nominal_in_s", "greater than 0"),
    ({"belts": {"input_nominal_in_s": True}}, "belts.input_nominal_in_s", "must be a number"),
    ({"belts": {"input_nominal_in_s": ".nan"}}, "belts.input_nominal_in_s", "must be a number"),
    ({"robot": {"motors": {"steps_per_rad": [1, 2, 3]}}}, "robot.motors.steps_per_rad",
     "exactly 5"),
    ({"robot": {"motors": {"nominal_fraction": 1.5}}}, "robot.motors.nominal_fraction",
     "at most 1"),
    ({"robot": {"timing": "fast"}}, "robot.timing", "one of"),
    ({"controller": {"policy": "random"}}, "controller.policy", "one of"),
    ({"arrivals": {"distribution": "no_such_dist"}}, "arrivals.distribution", "scipy.stats"),
    ({"arrivals": {"distribution": "poisson"}}, "arrivals.distribution", "continuous"),
    ({"arrivals": {"distribution": "norm", "params": {"mu": 3}}}, "arrivals.params",
     "norm takes loc, scale, not mu: give arrivals.params for norm"),
    ({"arrivals": {"distribution": "norm", "params": {"loc": 20, "scale": 1}}},
     "arrivals.params", "non-negative"),
    ({"arrivals": {"trace_csv": "missing.csv"}}, "arrivals.trace_csv", "no such file"),
    ({"path": {"lo_from_bot_in": 9.0}}, "path.lo_from_bot_in", "one move"),
    ({"robot": {"hand": {"open_in": 5.0}}}, "robot.hand.open_in", "linkage"),
    ({"path": "x"}, "path", "mapping"),
    ({"cell": {"belt_width_in": 1.5}}, "cell.belt_width_in", "does not fit"),
    ({"part": {"size_in": 3.0}, "cell": {"belt_width_in": 2.5}}, "part.size_in", "does not fit"),
]


@pytest.mark.parametrize("raw,key,why", BAD, ids=[b[1] + ":" + b[2] for b in BAD])
def test_bad_values_name_file_key_and_value(tmp_path, raw, key, why):
    f = tmp_path / "bad.yaml"
    f.write_text(yaml.safe_dump(raw) if not isinstance(raw, str) else raw)
    with pytest.raises(ScenarioError) as info:
        load_scenario(f)
    msg = str(info.value)
    assert msg.startswith(f"{f}: {key} = "), msg
    assert why in msg and "\n" not in msg


def test_trace_with_negative_time(tmp_path):
    (tmp_path / "trace.csv").write_text("interarrival_s\n20.0\n-1.5\n21.0\n")
    f = tmp_path / "s.yaml"
    f.write_text("arrivals:\n  trace_csv: trace.csv\n")
    with pytest.raises(ScenarioError, match=r"trace_csv = .*line 3 .*-1.5.*positive"):
        load_scenario(f)


def test_trace_resolves_beside_the_scenario(tmp_path):
    (tmp_path / "trace.csv").write_text("interarrival_s\n20.0\n21.0\n")
    f = tmp_path / "s.yaml"
    f.write_text("arrivals:\n  trace_csv: trace.csv\n")
    assert load_scenario(f).arrivals.trace_csv == "trace.csv"


def test_unreachable_path_point_is_a_scenario_error():
    s = from_dict({"path": {"bot_in": [-26.0, 0.0, 3.0]}}, "x.yaml")
    with pytest.raises(ScenarioError, match=r"x.yaml: path.bot_in = \[-26.0, 0.0, 3.0\]: "
                                            r"path point 0 .*out of reach"):
        step_table(s)
    s = from_dict({"path": {"pick_height_in": 14.0}}, "y.yaml")
    with pytest.raises(ScenarioError, match=r"y.yaml: path.pick_height_in = 14.0: .*theta"):
        step_table(s)


@pytest.mark.parametrize("key,value", [
    ("cell.robot_yaw_deg", 0.0), ("cell.robot_base_in", [-14.0, 8.0, 0.0]),
    ("cell.shoulder_height_in", 30.0), ("robot.l2_in", 3.0), ("robot.l3_in", 4.0),
    ("robot.hand.l1_in", 12.0), ("robot.joint_limits_deg.theta3", [-100.0, 0.0]),
    ("robot.joint_limits_deg.theta1", [-60.0, 60.0]), ("path.eot_in", [0.0, 24.0, 3.0]),
    ("path.bot_in", [-20.0, 0.0, 3.0]),
])
def test_an_unreachable_point_names_the_key_that_caused_it(tmp_path, key, value):
    """Whatever key puts a point out of reach, the error names that key and the file."""
    f = tmp_path / "what-if.yaml"
    f.write_text("name: what-if\n")
    s = load_scenario(f, {key: value})
    with pytest.raises(ScenarioError) as info:
        step_table(s)
    msg = str(info.value)
    assert msg.startswith(f"{f}: {key} = "), msg
    assert "\n" not in msg


def test_distribution_by_name_and_params():
    s = from_dict({"arrivals": {"distribution": "gamma",
                                "params": {"a": 4.0, "loc": 18.0, "scale": 1.0}}})
    assert s.arrivals.distribution == "gamma"
    assert np.isclose(s.arrivals.params["a"], 4.0)


def test_dotted_keys_reach_into_mappings_and_sections_merge():
    s = default_scenario()
    assert s.with_overrides({"arrivals.params.scale": 6.0}).arrivals.params == \
        {"c": WEIBULL_SHAPE, "loc": 17.6019, "scale": 6.0}
    kept = s.with_overrides({"run.parts": 77}).with_overrides({"run": {"seed": 9}})
    assert (kept.run.parts, kept.run.seed) == (77, 9)
    # a distribution's parameters belong together: a mapping given for them replaces them
    expon = s.with_overrides({"arrivals": {"distribution": "expon",
                                           "params": {"loc": 12.5872, "scale": 10.0}}})
    assert expon.arrivals.params == {"loc": 12.5872, "scale": 10.0}
    assert known_key("arrivals.params.scale") and not known_key("arrivals.params.a.b")


def test_set_on_the_command_line_reaches_into_mappings(tmp_path):
    from cell.scenario.overrides import parse_sets

    f = tmp_path / "s.yaml"
    f.write_text("run:\n")                      # an empty section
    s = load_scenario(f, parse_sets(["arrivals.params.scale=6.0", "run.parts=10"]))
    assert s.arrivals.params["scale"] == 6.0 and s.run.parts == 10


def test_a_file_without_a_name_goes_by_the_files_name(tmp_path):
    unnamed = tmp_path / "faster_belt.yaml"
    unnamed.write_text("belts: {input_nominal_in_s: 3.5}\n")
    named = tmp_path / "other.yaml"
    named.write_text("name: mine\n")
    assert load_scenario(unnamed).name == "faster_belt"
    assert load_scenario(named).name == "mine"
    assert load_scenario(unnamed, {"name": "given"}).name == "given"
    assert load_scenario("baseline").name == "baseline"
    for blank in ("name: ''\n", "name:\n"):
        named.write_text(blank)
        assert load_scenario(named).name == "other"
