"""A nominal cycle left off the arrivals' mean: ``cell sweep`` and ``cell compare`` warn once,
in ``cell run``'s words, as they warn of overload."""

from __future__ import annotations

import pytest

from cell.cli.main import main
from cell.experiments.sweep import load_sweep
from cell.experiments.sweep.spec import comparison
from cell.reporting.run_summary import nominal_warning
from cell.scenario.schema import load_scenario
from tests.prose import in_order

GAMMA = {"distribution": "gamma", "mean_s": 22.5872, "cv": 0.3}
#: What every such line ends with, run, sweep or compare.
SAID = "the controller aims at it, not at the arrivals; set it to null to follow them"


def nominal_lines(err: str) -> list[str]:
    return [line for line in err.splitlines() if "controller.nominal_cycle_s" in line]


def run_sweep_cli(sweeps, tmp_path, capsys, monkeypatch, **fields) -> list[str]:
    """``cell sweep`` of a sweep file over baseline.yaml (stand-in replications): its
    warning lines about the nominal cycle."""
    monkeypatch.setattr("cell.experiments.sweep.simulate_summary", sweeps.first_draw)
    path = sweeps.write(tmp_path, replications=2, batch=2, **fields)
    assert main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1"]) == 0
    return nominal_lines(capsys.readouterr().err)


def test_a_sweep_over_the_arrivals_mean_warns_once_naming_the_worst(sweeps, tmp_path, capsys,
                                                                   monkeypatch):
    """baseline.yaml states 22.5872 s: at 20 s it is 12.9 % long, at 25 s 9.6 % short, at
    22.5872 s right; one line for the two points, the worst named, the fix given."""
    (line,) = run_sweep_cli(sweeps, tmp_path, capsys, monkeypatch, policies=["adaptive"],
                            set={"run.parts": 10, "arrivals": GAMMA},
                            grid={"arrivals.mean_s": [22.5872, 25, 20]})
    off = f"{22.5872 / 20 - 1:+.1%}"  # the worst point's: 20 s
    assert in_order(line, "cell: warning: 2 of 3 points", "controller.nominal_cycle_s", off,
                    "22.5872 s", "20.0000 s", "arrivals.mean_s 20", SAID,
                    "{controller.nominal_cycle_s: null}", "sweep file")


@pytest.mark.parametrize("fields", [
    {},  # Table 7.1's layout: the arrivals are the thesis's, 22.5872 s is their mean
    {"policies": ["adaptive"], "grid": {"arrivals.mean_s": [20, 25]},
     "set": {"run.parts": 10, "arrivals": GAMMA, "controller.nominal_cycle_s": None}},
    {"policies": ["adaptive"], "grid": {"controller.nominal_cycle_s": [20.5, 22.5872]},
     "set": {"run.parts": 10}},  # the sweep's own choice, not the base's leftover
], ids=["arrivals-unchanged", "nominal-null", "nominal-varied"])
def test_a_sweep_that_keeps_the_nominal_on_its_arrivals_says_nothing(sweeps, tmp_path, capsys,
                                                                     monkeypatch, fields):
    assert run_sweep_cli(sweeps, tmp_path, capsys, monkeypatch, **fields) == []


def test_run_sweep_and_compare_say_it_in_the_same_words(sweeps, tmp_path):
    from cell.reporting.run_summary import warnings
    from cell.sim.assembly import assemble

    sweep = load_sweep(sweeps.write(tmp_path, policies=["adaptive"],
                                    set={"run.parts": 10, "arrivals": {**GAMMA, "mean_s": 20}}))
    (ran,) = warnings(assemble(sweep.points[0].scenario).k)
    off = f"{22.5872 / 20 - 1:+.1%}"
    assert ran.startswith("controller.nominal_cycle_s (22.5872 s)") and ran.endswith(SAID)
    assert in_order(ran, off, "(20.0000 s)")
    assert SAID in nominal_warning(sweep)


def test_compare_warns_once_for_both_sides(capsys):
    sets = ["--set", "arrivals.distribution=gamma", "--set", "arrivals.mean_s=20",
            "--set", "arrivals.cv=0.2", "--set", "run.parts=10"]
    assert main(["compare", "baseline", "non_adaptive", "--replications", "2", "--workers", "1",
                 *sets]) == 0
    (line,) = nominal_lines(capsys.readouterr().err)
    off = f"{22.5872 / 20 - 1:+.1%}"
    assert in_order(line, "cell: warning: baseline and non_adaptive",
                    "controller.nominal_cycle_s (22.5872 s)", off, "(20.0000 s)", SAID,
                    "(--set controller.nominal_cycle_s=null)")
    assert main(["compare", "baseline", "non_adaptive", "--replications", "2", "--workers", "1",
                 *sets, "--set", "controller.nominal_cycle_s=null"]) == 0
    assert nominal_lines(capsys.readouterr().err) == []


def test_compare_names_only_the_side_that_is_off():
    from cell.reporting.run_summary import comparison_nominal_warning as compare_warning

    a = load_scenario("baseline")
    b = a.with_overrides({"arrivals": {**GAMMA, "mean_s": 25}})
    text = compare_warning(comparison(a, b, ("a", "b"), 2, 1))
    off = f"{22.5872 / 25 - 1:+.1%}"
    assert text.startswith("b: controller.nominal_cycle_s") and "a: " not in text
    assert in_order(text, "(22.5872 s)", off, "(25.0000 s)")
    assert compare_warning(comparison(a, a.with_overrides({"run.seed": 2}), ("a", "b"), 2, 1)) \
        is None


def test_the_built_in_sweeps_warn_only_where_it_is_true(tmp_path):
    """Table 7.1 runs the thesis's arrivals, stress follows each point's (null); whatif keeps
    the thesis's robot on faster arrivals on purpose and says so in its own ``set:``, so none
    warns; whatif without that setting is told of the 5.3 % it keeps."""
    from cell.scenario import catalog

    for name in ("table_7_1", "table_7_1_mintime", "stress", "whatif"):
        assert nominal_warning(load_sweep(name)) is None, name
    text = catalog.path("whatif").read_text(encoding="utf-8")
    assert ", controller.nominal_cycle_s: 22.5872}" in text
    (tmp_path / "whatif.yaml").write_text(text.replace(", controller.nominal_cycle_s: 22.5872}",
                                                       "}"), encoding="utf-8")
    said = nominal_warning(load_sweep(tmp_path / "whatif.yaml"))
    off = f"{22.5872 / 21.4567 - 1:+.1%}"
    assert said is not None and said.startswith("4 of 8 points ")
    assert in_order(said, "controller.nominal_cycle_s", off, "22.5872 s", "21.4567 s",
                    "arrivals.params faster")
