"""The ``failures:`` section and ``run.hours`` given bad values: one line naming the file, the
key and the value, exit 2, nothing written (from ``--set`` and from a scenario file)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from .harness import cli, refused

R = "{distribution: expon, params: {scale: 600}}"


def robot(ttf: str, extra: str = "") -> str:
    return f"{{robot: {{time_to_failure: {ttf}, time_to_repair: {R}}}{extra}}}"


#: (id, the failures value, words the refusal must hold); a negative scale is a zero scale's rule
CASES = [
    ("zero mean time to failure", robot("{distribution: expon, params: {scale: 0}}"),
     ("failures.robot.time_to_failure.params", "scale", "zero or negative")),
    ("negative mean", robot("{distribution: norm, params: {loc: -600, scale: 10}}"),
     ("failures.robot.time_to_failure.params", "non-negative")),
    ("no finite mean", robot("{distribution: pareto, params: {b: 0.8}}"),
     ("failures.robot.time_to_failure.params", "no finite mean")),
    ("undefined mean (a Cauchy's, not a bad scale)", robot("{distribution: cauchy, params: {scale: 100}}"),
     ("failures.robot.time_to_failure.params", "cauchy with these has no finite mean")),
    ("no finite mean repair",
     f"{{input_belt: {{time_to_failure: {R}, time_to_repair: {{distribution: levy, params: {{}}}}}}}}",
     ("failures.input_belt.time_to_repair.params", "no finite mean")),
    ("no such distribution", robot("{distribution: gauss, params: {}}"),
     ("failures.robot.time_to_failure.distribution", "gauss")),
    ("zero crews", robot(R, ", repair: {crews: 0}"), ("failures.repair.crews", "0", "at least 1")),
    ("unknown equipment", f"{{conveyor: {{time_to_failure: {R}, time_to_repair: {R}}}}}",
     ("failures.conveyor", "unknown key", "robot, input_belt")),
    ("maintenance longer than its interval",
     robot(R, ", maintenance: {every_h: 1, duration_min: 90}"),
     ("failures.maintenance.duration_min", "90", "shorter than its interval")),
    ("unknown clock", f"{{robot: {{time_to_failure: {R}, time_to_repair: {R}, clock: wall}}}}",
     ("failures.robot.clock", "wall")),
    ("part in hand", f"{{robot: {{time_to_failure: {R}, time_to_repair: {R}, part_in_hand: drop}}}}",
     ("failures.robot.part_in_hand", "drop")),
    ("repair missing", f"{{robot: {{time_to_failure: {R}}}}}", ("failures.robot.time_to_repair",)),
    # no bound on simulated work: a failure a microsecond would stop a 5-part run 1e8 times
    ("failures every microsecond", robot("{distribution: expon, params: {scale: 0.000001}}"),
     ("failures.robot.time_to_failure.params", "1e-06")),
    ("planned stops every few milliseconds", robot(R, ", maintenance: {every_h: 0.000001, "
                                                   "duration_min: 0.00000001}"),
     ("failures.maintenance.every_h", "1e-06")),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_a_bad_failures_section_is_refused_in_one_line(tmp_path: Path, case: tuple) -> None:
    """Each through ``--set``; the first in a scenario file too (the file is named by the same
    rule whichever check of the section refuses it)."""
    _, value, words = case
    out = tmp_path / "out"
    refused(cli("run", "baseline", "--set", "run.parts=5", "--set", f"failures={value}",
                "--out", out), "baseline.yaml", *words, nothing_in=out)
    if case is not CASES[0]:
        return
    scenario = tmp_path / "bad.yaml"
    scenario.write_text(f"run: {{parts: 5}}\nfailures: {value}\n", encoding="utf-8")
    refused(cli("run", scenario, "--out", out), str(scenario), *words, nothing_in=out)


def test_hours_and_parts_together_are_refused(tmp_path: Path) -> None:
    out = tmp_path / "out"
    refused(cli("run", "baseline", "--set", "run.hours=2", "--set", "run.parts=30", "--out", out),
            "run.hours", "not both", nothing_in=out)


def test_hours_in_which_no_part_comes_are_refused(tmp_path: Path) -> None:
    out = tmp_path / "out"
    refused(cli("run", "baseline", "--set", "run.hours=0.001", "--out", out),
            "run.hours", "no part comes", nothing_in=out)


def test_a_mean_long_only_through_rare_enormous_draws_is_refused_as_a_storm(tmp_path: Path) -> None:
    """A lognormal of σ = 8 and median 1e-13 s has a mean of e^32 x 1e-13 = 7.9 s (above the 1 s
    floor), yet nearly every draw is shorter than a nanosecond: what bounds the stops of a run is
    the mean with times beyond the run cut at its length, not the mean."""
    import scipy.stats

    ttf = scipy.stats.lognorm(8.0, scale=1e-13)
    assert ttf.mean() > 1.0 and ttf.cdf(1e-9) > 0.5
    out = tmp_path / "out"
    value = robot("{distribution: lognorm, params: {s: 8, scale: 1.0e-13}}")
    refused(cli("run", "baseline", "--set", "run.parts=5", "--set", f"failures={value}", "--out", out),
            "failures.robot.time_to_failure.params", "1e-13", nothing_in=out)


def test_a_motor_life_of_milliseconds_is_refused(tmp_path: Path) -> None:
    out = tmp_path / "out"
    wear = "wear={enabled: true, rated_life_h: 1.0e-5}"
    refused(cli("run", "baseline", "--set", "run.parts=5", "--set", wear, "--out", out),
            "wear.rated_life_h", "1e-05", nothing_in=out)


def test_failures_a_second_apart_run(tmp_path: Path) -> None:
    """The floor's own value (a mean time to failure of 1 s, a repair of a millisecond) runs."""
    out = tmp_path / "out"
    value = robot("{distribution: expon, params: {scale: 1}}").replace("600", "0.001")
    res = cli("run", "baseline", "--set", "run.parts=5", "--set", f"failures={value}", "--out", out)
    res.case.judged("ran")
    assert res.code == 0, res.err
    assert len(pd.read_csv(out / "failures.csv")) > 20  # about 80 s of motion: some 50 failures


def test_hours_and_parts_given_together_in_a_file_are_refused_whatever_the_parts(tmp_path: Path) -> None:
    """Both given is refused even when run.parts is its default, 500 (once compared with it)."""
    scenario = tmp_path / "both.yaml"
    scenario.write_text("run: {parts: 500, hours: 1}\n", encoding="utf-8")
    out = tmp_path / "out"
    refused(cli("run", scenario, "--out", out), str(scenario), "run.hours", "500", nothing_in=out)
