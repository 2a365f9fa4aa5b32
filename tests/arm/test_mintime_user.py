"""What a user of minimum-time timing sees: the planner's defaults, the line naming its
bounds, a drive too weak for the arm, and ``cell mintime``'s files."""

from __future__ import annotations

import pytest

from cell.arm.mintime.regimes import fastest_regime_times, plan_regimes
from cell.cli.main import main
from cell.scenario.schema import load_scenario
from cell.sim.scenario_values import geometry_of, motors_of, planner_bounds
from tests.prose import error_parts, in_order

KIN = load_scenario("mintime_kinematic")


def _fastest(s):
    return fastest_regime_times(geometry_of(s), motors_of(s), planner_bounds(s))


def test_a_small_file_under_minimum_time_plans_as_the_baseline(tmp_path):
    """A key left out of a what-if file is baseline.yaml's: the dynamic model, no assumed
    acceleration bounds, so the same R II and R IV as the baseline under minimum-time timing."""
    mine = tmp_path / "mt_only.yaml"
    mine.write_text("name: mt-only\nrobot:\n  timing: minimum-time\n")
    s = load_scenario(mine)
    assert s.mintime.dynamics_file == "microbot_dynamics.yaml"
    assert s.mintime.acceleration_bounds is False
    base = load_scenario("baseline", {"robot.timing": "minimum-time"})
    assert _fastest(s) == _fastest(base)
    # a dynamics file of the user's own is then the only bound on the accelerations
    heavy = tmp_path / "heavy_dyn.yaml"
    heavy.write_text("links: {mass_kg: [1.6, 0.6, 0.5, 0.10, 0.20]}\n")
    own = load_scenario(mine, {"mintime.dynamics_file": str(heavy)})
    assert _fastest(own)["R2"] > _fastest(s)["R2"]


def test_cell_run_and_cell_mintime_name_the_planners_bounds(tmp_path, capsys):
    """Under minimum-time timing the heading names the bounds in one line; the two planners
    (dynamic model, assumed acceleration bounds) can be told apart from the output alone."""
    runs = {"dynamic": ["baseline"],
            "kinematic": ["mintime_kinematic", "--set", "mintime.rate_fraction=0.5"]}
    lines = {}
    for label, args in runs.items():
        assert main(["run", *args, "--set", "robot.timing=minimum-time", "--set", "run.parts=3",
                     "--out", str(tmp_path / label)]) == 0
        out = capsys.readouterr().out.splitlines()
        lines[label] = [ln for ln in out if ln.startswith("minimum-time planner:")]
    dyn, = lines["dynamic"]
    assert "dynamic model " in dyn and dyn.endswith("; dynamic model microbot_dynamics")
    assert "acceleration" not in dyn and "at the motors' peak rates" in dyn
    kin, = lines["kinematic"]
    assert "dynamic model" not in kin and "0.5 × the motors' peak rates" in kin
    bounds = ", ".join(f"{b:g}" for b in KIN.mintime.qddot_max_rad_s2)
    assert in_order(kin, "assumed acceleration bounds", f"[{bounds}] rad/s²") and kin.endswith("²")
    assert main(["run", "baseline", "--set", "run.parts=3", "--out", str(tmp_path / "c")]) == 0
    assert "planner" not in capsys.readouterr().out       # constant-rate timing plans nothing
    assert main(["mintime", "baseline", "--out", str(tmp_path / "m")]) == 0
    assert dyn in capsys.readouterr().out.splitlines()
    # a file of the user's own is named as given
    own = tmp_path / "own_dyn.yaml"
    own.write_text("gravity_m_s2: 9.81\n")
    assert main(["mintime", "baseline", "--set", f"mintime.dynamics_file={own}",
                 "--out", str(tmp_path / "own")]) == 0
    assert capsys.readouterr().out.splitlines()[0].endswith(f"; dynamic model {own}")


def _dynamics(tmp_path, name, key, values):
    """A copy of the built-in dynamics file with one list replaced."""
    import re

    from cell.scenario import catalog

    text = catalog.path("microbot_dynamics.yaml").read_text()
    text, n = re.subn(rf"(?m)^(\s*{key}:).*$", rf"\1 {values}", text)
    assert n == 1
    (tmp_path / name).write_text(text)
    return str(tmp_path / name)


def _needed(err):
    """{joint number: torque} that a weak-drive line names."""
    import re

    return {int(j): float(v) for j, v in re.findall(r"\(joint (\d)\) (?:needs )?([\d.]+) N·m", err)}


def test_a_drive_too_weak_for_the_arm_names_the_file_key_joint_and_torques(tmp_path, capsys):
    """The shoulder's stall torque below what holding the arm at rest takes: one line naming
    the dynamics file, its key and value, the joint and both torques; nothing written.  The
    torque named is the most any point of either regime needs (R IV's, a little past its
    start), whichever point the planner stopped at: a drive given that much plans."""
    out = tmp_path / "out"
    for stall in ("0.5", "1.39", "1.42"):
        weak = _dynamics(tmp_path, "weak.yaml", "stall_torque_nm", f"[3.1, {stall}, 1.66, 1.14, 1.14]")
        for command in (["mintime"], ["run", "--set", "robot.timing=minimum-time"]):
            args = [command[0], "baseline", *command[1:], "--set", f"mintime.dynamics_file={weak}"]
            assert main([*args, "--out", str(out)]) == 2
            err = capsys.readouterr().err
            assert err.count("\n") == 1 and not out.exists()
            line = error_parts(err.removeprefix("cell: error: "))
            assert (line.file, line.key) == (weak, "drives.stall_torque_nm")
            assert line.value.startswith(f"[3.1, {stall}, ")
            assert in_order(line.why, "the shoulder (joint 2)", "1.62 N·m", "gravity",
                            "s = 0.0466 of R4", f"stall torque {stall} N·m")
            assert _needed(err) == {2: 1.62}
    enough = _dynamics(tmp_path, "ok.yaml", "stall_torque_nm", "[3.1, 1.62, 1.66, 1.14, 1.14]")
    assert main(["mintime", "baseline", "--set", f"mintime.dynamics_file={enough}",
                 "--out", str(out)]) == 0


def test_every_weak_drive_is_named_with_the_torque_that_holds(tmp_path, capsys):
    """Under a stronger gravity the shoulder and the elbow both fall short: both are named, each
    with the most it needs anywhere; given exactly those torques, the planner plans."""
    base = _dynamics(tmp_path, "g.yaml", "gravity_m_s2", "30.0")
    assert main(["mintime", "baseline", "--set", f"mintime.dynamics_file={base}",
                 "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    need = _needed(err)
    assert sorted(need) == [2, 3] and need[2] > 3.4 and need[3] > 1.66
    assert err.count("\n") == 1 and "the shoulder (joint 2) needs" in err and "; the elbow" in err
    text = (tmp_path / "g.yaml").read_text()
    assert "stall_torque_nm: [3.1, 3.40, 1.66," in text
    text = text.replace("stall_torque_nm: [3.1, 3.40, 1.66,", f"stall_torque_nm: [3.1, {need[2]}, {need[3]},")
    (tmp_path / "g.yaml").write_text(text)
    assert main(["mintime", "baseline", "--set", f"mintime.dynamics_file={base}",
                 "--out", str(tmp_path / "out")]) == 0


def test_links_too_heavy_name_the_masses(tmp_path, capsys):
    heavy = _dynamics(tmp_path, "heavy.yaml", "mass_kg", "[1.6, 0.9, 0.75, 0.30, 0.40]")
    assert main(["mintime", "baseline", "--set", f"mintime.dynamics_file={heavy}",
                 "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    line = error_parts(err.removeprefix("cell: error: "))
    assert (line.file, line.key, line.value) == (heavy, "links.mass_kg", "[1.6, 0.9, 0.75, 0.3, 0.4]")
    assert in_order(line.why, "the shoulder (joint 2)", "stall torque 3.4 N·m", "model of baseline)")


@pytest.mark.parametrize(("text", "named"), [
    ("gravity_m_s2: 30.0\n", "gravity_m_s2 = 30.0"),
    ("links:\n  com_m: [[0, -0.03, 0], [1.0, 0, 0], [-0.0889, 0, 0], [0, 0, 0], [0, 0, 0.03]]\n",
     "links.com_m = [[0.0, -0.03, 0.0], [1.0, 0.0, 0.0], "),
])
def test_a_weak_drive_is_blamed_on_the_key_that_differs_from_the_built_in_file(
        tmp_path, capsys, text, named):
    """Gravity or a centre of mass changed (a file of that key alone), the stall torques left
    as they were: the line names the changed key, not the drives."""
    mine = tmp_path / "mine.yaml"
    mine.write_text(text)
    assert main(["mintime", "baseline", "--set", f"mintime.dynamics_file={mine}",
                 "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"cell: error: {mine}: {named}") and "differ" not in err
    assert "to hold the arm against gravity" in err and "stall_torque" not in err


def test_a_weak_drive_names_every_changed_key_but_not_a_stronger_drive(tmp_path, capsys):
    """Heavier links under a stronger gravity, the shoulder's drive made stronger (still too
    weak): the masses are named, gravity beside them, the stronger drive not at all."""
    text = tmp_path / "m.yaml"
    _dynamics(tmp_path, "m.yaml", "mass_kg", "[1.6, 0.9, 0.75, 0.30, 0.40]")
    body = text.read_text()
    for old, new in (("gravity_m_s2: 9.80665", "gravity_m_s2: 12.0"),
                     ("stall_torque_nm: [3.1, 3.40,", "stall_torque_nm: [3.1, 3.6,")):
        assert old in body
        body = body.replace(old, new)
    text.write_text(body)
    assert main(["mintime", "baseline", "--set", f"mintime.dynamics_file={text}",
                 "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    line = error_parts(err.removeprefix("cell: error: "))
    assert (line.file, line.key) == (str(text), "links.mass_kg") and line.value.startswith("[1.6, 0.9, ")
    assert in_order(line.why, "model of baseline;", "gravity_m_s2 differs", "microbot_dynamics.yaml")
    assert "stall_torque" not in err


def test_elapsed_time_is_the_planners_time_sum():
    """t_s: 0 at the start, the profile's time_s bit for bit at the end (math.fsum), and s
    itself where ṡ = 1 throughout."""
    import math

    import numpy as np

    from cell.arm.mintime.planner import elapsed_s

    s = np.linspace(0.0, 1.0, 7) ** 2
    assert elapsed_s(s, np.ones(7)) == pytest.approx(s, abs=1e-15)
    sdot = np.array([0.0, 0.3, 0.7, 1e-3, 2.0, 0.5, 0.0])
    t = elapsed_s(s, sdot)
    terms = 2 * np.diff(s) / (sdot[1:] + sdot[:-1])
    assert t[0] == 0 and list(t[1:]) == [math.fsum(terms[:i]) for i in range(1, 7)]
    res = plan_regimes(geometry_of(KIN), motors_of(KIN), planner_bounds(KIN))
    for r in res.values():
        assert elapsed_s(r.profile.s, r.profile.sdot)[-1] == r.profile.time_s


@pytest.mark.parametrize(("args", "line"), [
    (["baseline", "--set", "mintime.dynamics_file=null"],
     "baseline.yaml (--set): mintime.dynamics_file = None: with mintime.acceleration_bounds false"),
    (["mintime_kinematic", "--set", "mintime.acceleration_bounds=false"],
     "mintime_kinematic.yaml (--set): mintime.acceleration_bounds = False: with "
     "mintime.dynamics_file empty"),
    (["{own}"], "own.yaml: mintime.acceleration_bounds = False: with mintime.dynamics_file empty"),
])
def test_nothing_bounding_the_accelerations_blames_the_key_given(tmp_path, capsys, args, line):
    """Neither a dynamics file nor acceleration bounds: the line names the key the command
    line emptied, marked (--set); both in the file itself: the file's, unmarked."""
    own = tmp_path / "own.yaml"
    own.write_text("mintime:\n  dynamics_file: null\n")
    args = [a.replace("{own}", str(own)) for a in args]
    assert main(["mintime", *args, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and line in err and "nothing bounds" in err
    assert ("(--set)" in err) == ("--set" in args)
