"""Times that look like milliseconds where seconds are read (cell.reporting.unit_slips): a warning
naming the likely mix-up, and the kilometre-long input belt it derives, not a refusal."""

from __future__ import annotations

from pathlib import Path

import pytest

from cell.cli.main import main
from cell.reporting.unit_slips import CYCLE_RATIO, LOW_OFFERED_LOAD, unit_warnings
from cell.scenario.schema import default_scenario
from cell.sim.assembly import assemble
from tests.prose import in_order

BASE = default_scenario().with_overrides({"run.parts": 20})


def warned(**overrides: object) -> list[str]:
    return unit_warnings(assemble(BASE.with_overrides(overrides)))


def test_the_thesis_cell_and_its_neighbours_get_no_warning() -> None:
    assert warned() == []
    mean = assemble(BASE).k.mean_interarrival_s
    assert warned(**{"controller.nominal_cycle_s": 0.99 * CYCLE_RATIO * mean}) == []
    assert warned(**{"controller.nominal_cycle_s": 1.01 * mean / CYCLE_RATIO}) == []


def test_a_mean_in_milliseconds_is_named_with_the_belt_it_makes() -> None:
    lines = warned(**{"arrivals.distribution": "gamma", "arrivals.mean_s": 22_000, "arrivals.cv": 0.3})
    assert len(lines) == 1
    assert lines[0].startswith("offered load 0.000")
    assert "a part every 22000 s on average (6.11 h)" in lines[0]
    assert in_order(lines[0], "milliseconds?", "arrivals.mean_s", "in seconds")
    assert "is 132000 in (3.35 km)" in lines[0]  # 2 x 3 in/s x 22000 s
    assert warned(**{"arrivals.distribution": "gamma", "arrivals.mean_s": 22_000, "arrivals.cv": 0.3,
                     "belts.input_length_in": 135.5})[0].endswith("is read in seconds")


def test_the_offered_load_threshold() -> None:
    k = assemble(BASE).k
    slow = k.fastest_cycle_s / LOW_OFFERED_LOAD
    expon = {"arrivals.distribution": "expon", "arrivals.cv": 1}
    assert warned(**expon, **{"arrivals.mean_s": 0.99 * slow}) == []
    assert len(warned(**expon, **{"arrivals.mean_s": 1.01 * slow})) == 1


@pytest.mark.parametrize("cycle, words, belt", [
    (22587.0, "controller.nominal_cycle_s = 22587 s (6.27 h) is 1000 times the arrivals' mean", True),
    (0.0226, "controller.nominal_cycle_s = 0.0226 s is 1/999 of the arrivals' mean", False),
])
def test_a_nominal_cycle_a_thousand_times_off(cycle: float, words: str, belt: bool) -> None:
    lines = warned(**{"controller.nominal_cycle_s": cycle})
    assert len(lines) == 1 and lines[0].startswith(words) and "milliseconds for seconds" in lines[0]
    assert ("is 135522 in (3.44 km)" in lines[0]) == belt


def test_cell_run_warns_of_a_trace_in_milliseconds_and_runs(tmp_path: Path, capsys) -> None:
    (tmp_path / "msv.csv").write_text("interarrival_s\n20000\n22000\n25000\n")
    scenario = tmp_path / "s.yaml"
    scenario.write_text("arrivals: {trace_csv: msv.csv}\nrun: {parts: 5}\n")
    assert main(["run", str(scenario), "--out", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err
    mean = (20000 + 22000 + 25000) / 3
    load = assemble(BASE).k.fastest_cycle_s / mean
    assert in_order(err, f"cell: warning: offered load {load:.2g}", f"every {mean:.1f} s",
                    f"({mean / 3600:.1f} h)", "milliseconds?", "arrivals.trace_csv (msv.csv)", "in seconds")
    assert (tmp_path / "out" / "summary.csv").is_file()


@pytest.mark.parametrize("cycle, said", [
    ("22587", ("controller.nominal_cycle_s = 22587 s", f"({22587 / 3600:.2f} h)",
               f"{22587 / 22.586:.0f} times", "(22.586 s)", "milliseconds for seconds", "null",
               "input belt's length")),
    ("30", ("controller.nominal_cycle_s (30.0000 s)", f"{30 / 22.586 - 1:+.1%} off", "(22.5860 s)",
            "null")),
])
def test_cell_run_says_a_nominal_cycle_off_the_arrivals_once(tmp_path: Path, capsys, cycle: str,
                                                             said: str) -> None:
    """A cycle in milliseconds: one line, the unit slip and what the controller does with it
    (not a second line of +99904.5 %); a cycle merely off: the percentage line, as before."""
    assert main(["run", "baseline", "--set", f"controller.nominal_cycle_s={cycle}",
                 "--set", "run.parts=3", "--out", str(tmp_path / "out")]) == 0
    captured = capsys.readouterr()
    (line,) = [ln for ln in captured.err.splitlines() if "nominal_cycle_s" in ln]
    assert line.startswith(f"cell: warning: {said[0]}") and in_order(line, *said)
    assert captured.err.count("cell: warning:") == 1
    assert in_order(captured.out, f"nominal cycle {float(cycle):.4f} s", "(controller.nominal_cycle_s)")
