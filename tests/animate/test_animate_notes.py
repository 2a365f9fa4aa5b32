"""What ``cell animate`` says besides the file: the memory refusal's advice fits the
machine, an overloaded cell is warned of as ``cell run`` warns, and parts past the
scenario's run get a note."""

from __future__ import annotations

from pathlib import Path

import pytest

from cell.cli.main import main as cli
from cell.plumbing.errors import CellError
from cell.reporting.animation.movie import animate
from cell.scenario.schema import Scenario
from tests.prose import in_order


@pytest.mark.parametrize("ffmpeg", [True, False])
def test_the_memory_refusal_suggests_an_mp4_only_with_ffmpeg(
        tmp_path: Path, scenario: Scenario, monkeypatch: pytest.MonkeyPatch, ffmpeg: bool) -> None:
    from matplotlib.animation import writers

    monkeypatch.setattr(writers, "is_available", lambda name: ffmpeg)
    with pytest.raises(CellError, match="raise --speed, lower --dpi or --parts") as info:
        animate(scenario, tmp_path / "a.gif", parts=12, speed=0.05, progress=False)
    assert ("write a .mp4" in str(info.value)) == ffmpeg
    assert list(tmp_path.iterdir()) == []


def said(capsys: pytest.CaptureFixture[str]) -> list[str]:
    """The lines on stderr that are not progress."""
    return [line for line in capsys.readouterr().err.splitlines() if " frames (" not in line]


def test_an_overloaded_cell_is_warned_of_as_cell_run_warns(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scenario = tmp_path / "overload.yaml"
    scenario.write_text("name: overload\n"
                        "arrivals: {distribution: weibull_min, mean_s: 16.0, cv: 0.05}\n"
                        "run: {parts: 20}\n")
    assert cli(["run", str(scenario), "--out", str(tmp_path / "run")]) == 0
    run = said(capsys)
    assert len(run) == 1 and run[0].startswith("cell: warning: offered load 1.130: ")
    assert cli(["animate", str(scenario), "--out", str(tmp_path / "a.gif"), "--parts", "1",
                "--speed", "200", "--dpi", "20"]) == 0
    assert said(capsys) == run


def test_parts_past_the_run_get_a_note(tmp_path: Path,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    from cell.cli.animate import notes
    from cell.scenario.schema import load_scenario

    # parts 4-5: within the run, nothing to say (the lines the command prints are notes')
    assert notes(load_scenario("baseline", {"run.parts": 5}), 4, 2) == []
    common = ["animate", "baseline", "--set", "run.parts=5", "--out", str(tmp_path / "a.gif"),
              "--speed", "200", "--dpi", "20", "--parts", "2"]
    assert cli([*common, "--from-part", "5"]) == 0
    (note,) = said(capsys)
    assert in_order(note, "cell: note: --from-part 5 --parts 2", "up to 6", "run.parts = 5",
                    "simulated on past its end")


def test_a_run_of_hours_is_animated_and_its_parts_counted_from_its_hours(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A scenario with run.hours animates (the window's run is of parts: it was refused as
    giving both), and the note counts the parts the hours bring, 0.1 h / 22.586 s: about 16."""
    from cell.cli.animate import notes
    from cell.scenario.schema import load_scenario

    assert notes(load_scenario("baseline", {"run.hours": 0.1}), 15, 2) == []  # parts 15-16
    common = ["animate", "baseline", "--set", "run.hours=0.1", "--out", str(tmp_path / "a.gif"),
              "--speed", "200", "--dpi", "20", "--parts", "2"]
    assert cli([*common, "--from-part", "16"]) == 0
    (note,) = said(capsys)
    assert in_order(note, "cell: note: --from-part 16 --parts 2", "up to 17",
                    f"about {round(0.1 * 3600 / 22.586)} ", "run.hours = 0.1", "simulated on past its end")


def test_both_policies_show_a_fixed_robot_at_its_own_cycle(tmp_path: Path) -> None:
    """``--policy both`` of a non-adaptive scenario with its own cycle: the fixed panel runs
    at that cycle, the adaptive one at the nominal cycle (it used to be refused: the adaptive
    policy takes no ideal_cycle_s)."""
    from cell.reporting.animation.movie import simulate_scenes
    from cell.scenario.schema import load_scenario

    s = load_scenario("non_adaptive", {"controller.ideal_cycle_s": 21.0})
    adaptive, fixed = simulate_scenes(s, ["adaptive", "non-adaptive"], 1, 2, progress=False)
    assert adaptive.scenario.controller.ideal_cycle_s is None
    assert fixed.scenario.controller.ideal_cycle_s == 21.0
    assert cli(["animate", "non_adaptive", "--set", "controller.ideal_cycle_s=21.0", "--policy",
                "both", "--out", str(tmp_path / "b.gif"), "--parts", "1", "--speed", "200",
                "--dpi", "20"]) == 0


def test_a_nominal_cycle_in_ms_is_warned_of_as_cell_run_warns(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """One line for the slip (its unit), not that and a percentage, from animate as from run."""
    common = ["--set", "controller.nominal_cycle_s=22587", "--set", "run.parts=2"]
    assert cli(["run", "baseline", *common, "--out", str(tmp_path / "run")]) == 0
    run = said(capsys)
    assert len(run) == 1 and "ms" in run[0] and "%" not in run[0], run
    from cell.cli.animate import notes
    from cell.scenario.schema import load_scenario

    scenario = load_scenario("baseline", {"controller.nominal_cycle_s": 22587, "run.parts": 2})
    assert [f"cell: {line}" for line in notes(scenario, 1, 1)] == run
