"""Values the schema's types and bounds allow but the cell's physics does not, and sweeps.

Each case states what the promise requires; those that fail today because of code in files
this suite's owner does not edit are marked ``xfail(strict=True)`` with the file and the
fix, so that they turn into failures to remove the marker from once fixed.
"""

from __future__ import annotations

import re
import signal
import time
from pathlib import Path

import pytest

from .harness import cli, ran_sanely, refused, tree

ROOT = Path(__file__).resolve().parents[2]


def _hole(reason: str) -> pytest.MarkDecorator:
    return pytest.mark.xfail(strict=True, reason=reason)


def _id(case: object) -> str:
    return str(case.values[0] if hasattr(case, "values") else case[0])  # type: ignore[index]


def _trace(tmp: Path, values: list[str]) -> Path:
    path = tmp / "trace.csv"
    path.write_text("interarrival_s\n" + "\n".join(values) + "\n")
    return path


#: (id, --set values, words the refusal must hold); a trace file is written when a value says {trace:...}.
#: One case per rule (tests/hostile/harness.py): a trace's -inf is nan's rule, 1e308 is 2e6's (too
#: long a gap), arrivals 1e300 s apart 1e9's, rv_continuous any name that is no distribution's
REFUSE = [
    ("a part too heavy for the shoulder", ["part.weight_oz=30"], ("part.weight_oz", "27.43 oz", "shoulder")),
    ("part wider than the hand opens", ["part.size_in=9"], ("part.size_in",)),
    ("window B-F shorter than LO", ["path.lo_from_bot_in=9"], ("path.lo_from_bot_in",)),
    ("max below nominal", ["belts.input_max_in_s=1"], ("belts.input_max_in_s",)),
    ("belt faster than the arm tracks", ["belts.input_nominal_in_s=900", "belts.input_max_in_s=1000"],
     ("belts.input_nominal_in_s",)),
    ("point out of reach", ["path.g_in=[0, 80, 3]"], ("path.g_in",)),
    ("joint limits inverted", ["robot.joint_limits_deg.theta1=[90, -90]"], ("theta1",)),
    ("negative inter-arrival times", ["arrivals.distribution=norm", "arrivals.params={loc: 22, scale: 3}"],
     ("arrivals.params", "non-negative")),
    ("no finite mean", ["arrivals.distribution=cauchy", "arrivals.params={loc: 22, scale: 3}"],
     ("arrivals.params",)),
    ("a distribution scipy lacks", ["arrivals.distribution=bogus"], ("arrivals.distribution",)),
    ("bogus distribution beside a trace", ["arrivals.distribution=bogus", "arrivals.trace_csv={trace:22}"],
     ("arrivals.distribution",)),
    ("trace value True", ["arrivals.trace_csv={trace:True}"], ("arrivals.trace_csv", "True")),
    ("trace value -0.5", ["arrivals.trace_csv={trace:-0.5}"], ("arrivals.trace_csv", "line 3")),
    ("trace value nan", ["arrivals.trace_csv={trace:nan}"], ("arrivals.trace_csv",)),
    ("trace missing", ["arrivals.trace_csv=nowhere.csv"], ("arrivals.trace_csv", "no such file")),
    ("trace is a directory", ["arrivals.trace_csv=."], ("arrivals.trace_csv",)),
    ("minimum-time without any bound", ["robot.timing=minimum-time", "mintime.dynamics_file=null",
                                         "mintime.acceleration_bounds=false"], ("minimum-time",)),
    ("minimum-time, dynamics file missing", ["robot.timing=minimum-time", "mintime.dynamics_file=no.yaml"],
     ("mintime.dynamics_file", "no such file")),
    ("minimum-time, planner too slow", ["robot.timing=minimum-time", "mintime.rate_fraction=1e-9"],
     ("mintime.rate_fraction", "at most")),
    ("arrivals 1e9 s apart", ["arrivals.params={c: 4.9, loc: 1e9, scale: 5.4}"], ("arrivals.params",)),
    ("trace value 2e6", ["arrivals.trace_csv={trace:2e6}"], ("arrivals.trace_csv", "line 3")),
    ("spacing smaller than a part", ["belts.spacing_in=1.0"], ("belts.spacing_in", "overlap")),
    ("tolerance wider than the spacing", ["belts.spacing_tol_in=250"],
     ("belts.spacing_tol_in", "overlap")),
    ("base motor too coarse for the path", ["robot.motors.steps_per_rad=[1e-9, 1125, 672, 241, 241]"],
     ("robot.motors.steps_per_rad",)),
    ("a part too heavy to track the output belt", ["part.weight_oz=10"], ("part.weight_oz", "TD")),
    ("LO at B", ["path.lo_from_bot_in=1e-300"], ("path.lo_from_bot_in", "one move")),
    ("B on F", ["path.bot_in=[-8.0, 0.0, 3.0]"], ("path.bot_in", "window")),
    ("drives too weak for the rates",
     ["robot.timing=minimum-time", "robot.motors.max_rate_no_load_rad_s=[1e9, 1, 1, 3, 3]"],
     ("robot.motors.max_rate_no_load_rad_s", "stall torque")),
    ("motors too slow for any regime", ["robot.motors.max_rate_no_load_rad_s=[1e-9, 1, 1, 3, 3]"],
     ("robot.motors.max_rate_no_load_rad_s", "at most")),
]


@pytest.mark.parametrize("label,sets,words", REFUSE, ids=[_id(c) for c in REFUSE])
def test_physics_refused(tmp_path: Path, label: str, sets: list[str], words: tuple[str, ...]) -> None:
    args = []
    for s in sets:
        if "{trace:" in s:
            key, _, value = s.partition("={trace:")
            s = f"{key}={_trace(tmp_path, ['22.5', value.rstrip('}'), '23.0'])}"
        args += ["--set", s]
    out = tmp_path / "out"
    res = cli("run", "baseline", "--set", "run.parts=5", *args, "--out", out)
    line = refused(res, *words, nothing_in=out)
    assert not re.search(r"\d{25}", line), f"a number of 25 digits or more: {line}"


@pytest.mark.parametrize("sets", [
    ["arrivals.distribution=truncnorm", "arrivals.params={a: -2, b: .inf, loc: 22.5872, scale: 2}"],
    ["arrivals.distribution=expon", "arrivals.params={loc: 17, scale: 5.6}"],
    ["arrivals.params={c: 1e300}"],  # every part 1 s after the last: parts are lost, the books balance
    ["controller.policy=non-adaptive", "controller.ideal_cycle_s=21e0"],
    ["part.weight_oz=0"], ["part.weight_oz=6"],
    ["run.seed=340282366920938463463374607431768211455"],
    ["controller.nominal_cycle_s=1e6"], ["controller.nominal_cycle_s=5"], ["controller.nominal_cycle_s=null"],
    ["run.warmup_parts=auto"], ["run.warmup_parts=4"],
    ["belts.input_length_in=1e-300"],
    ["robot.timing=minimum-time"],
], ids=lambda s: " ".join(s)[:60])
def test_valid_input_runs(tmp_path: Path, sets: list[str]) -> None:
    out = tmp_path / "out"
    args = [a for s in sets for a in ("--set", s)]
    ran_sanely(cli("run", "baseline", "--set", "run.parts=5", *args, "--out", out), out, 5)


def test_a_trace_is_used_whatever_the_distribution_says(tmp_path: Path) -> None:
    trace = _trace(tmp_path, ["22.5", "23.5", "21.0"])
    out = tmp_path / "out"
    ran_sanely(cli("run", "baseline", "--set", "run.parts=4", "--set", f"arrivals.trace_csv={trace}",
                   "--set", "arrivals.distribution=norm", "--out", out), out, 4)


def test_a_trace_with_zero_gaps_runs(tmp_path: Path) -> None:
    """Two parts logged in the same second: the second is held at the feeder, not refused."""
    trace = _trace(tmp_path, ["0", "22.5", "0", "23.5", "0"])
    out = tmp_path / "out"
    summary = ran_sanely(cli("run", "baseline", "--set", "run.parts=6", "--set",
                             f"arrivals.trace_csv={trace}", "--out", out), out, 6)
    assert summary.parts_held >= 2


# --- sweeps ------------------------------------------------------------------------------------

def _sweep(tmp: Path, text: str) -> Path:
    (tmp / "base.yaml").write_text("run: {parts: 4}\n")
    path = tmp / "sweep.yaml"
    path.write_text(text)
    return path


SWEEP_REFUSE = [
    ("no base", "replications: 2\n", ("base",)),
    ("base missing", "base: nowhere.yaml\nreplications: 2\n", ("nowhere.yaml",)),
    ("unknown key", "base: base.yaml\nreplications: 2\nreplicas: 3\n", ("replicas",)),
    ("replications 0", "base: base.yaml\nreplications: 0\n", ("replications",)),
    ("replications text", "base: base.yaml\nreplications: many\n", ("replications",)),
    ("replications true", "base: base.yaml\nreplications: true\n", ("replications",)),
    ("seed negative", "base: base.yaml\nreplications: 2\nseed: -1\n", ("seed",)),
    ("batch 0", "base: base.yaml\nreplications: 2\nbatch: 0\n", ("batch",)),
    ("grid not a mapping", "base: base.yaml\nreplications: 2\ngrid: [1, 2]\n", ("grid",)),
    ("grid value not a list", "base: base.yaml\nreplications: 2\ngrid: {run.parts: 5}\n", ("run.parts",)),
    ("grid empty list", "base: base.yaml\nreplications: 2\ngrid: {run.parts: []}\n", ("run.parts",)),
    ("grid unknown key", "base: base.yaml\nreplications: 2\ngrid: {run.prts: [1]}\n", ("run.prts",)),
    ("grid bad value", "base: base.yaml\nreplications: 2\ngrid: {run.parts: [3, -1]}\n", ("run.parts",)),
    ("grid value twice", "base: base.yaml\nreplications: 2\ngrid: {run.parts: [3, 3]}\n", ("listed twice",)),
    ("grid sets the seed", "base: base.yaml\nreplications: 2\ngrid: {run.seed: [1, 2]}\n", ("run.seed",)),
    ("grid section sets the policy", "base: base.yaml\nreplications: 2\n"
     "grid: {controller: [{policy: non-adaptive}]}\n", ("controller",)),
    ("policy unknown", "base: base.yaml\nreplications: 2\npolicies: [sloppy]\n", ("sloppy",)),
    ("policies empty", "base: base.yaml\nreplications: 2\npolicies: []\n", ("policies",)),
    ("duplicate keys", "base: base.yaml\nreplications: 2\nreplications: 3\n", ("duplicate key",)),
    ("a million points", "base: base.yaml\nreplications: 2\ngrid:\n" + "".join(
        f"  {k}: [{', '.join(str(v) for v in vs)}]\n" for k, vs in (
            ("run.parts", range(1, 101)), ("belts.spacing_tol_in", [i / 10 for i in range(1, 101)]),
            ("belts.spacing_in", range(40, 140)))), ("grid",)),
    ("10^8 replications", "base: base.yaml\nreplications: 100000000\n", ("replications",)),
]


@pytest.mark.parametrize("label,text,words", SWEEP_REFUSE,
                         ids=[_id(c) for c in SWEEP_REFUSE])
def test_sweep_refused(tmp_path: Path, label: str, text: str, words: tuple[str, ...]) -> None:
    """Refused in one line naming the sweep file and the key, quickly, nothing written."""
    if label in ("a million points", "10^8 replications"):  # a hang must not stall the suite
        # in this process, stopped by an alarm well under the minutes a checked million points
        # would take, with room for a loaded machine running the suite on every core (what the
        # alarm raises is no error of cell's: it goes through main() as a bug would)
        def hung(signum: int, frame: object) -> None:
            raise _Hung(label)

        before = signal.signal(signal.SIGALRM, hung)
        signal.setitimer(signal.ITIMER_REAL, 30)
        try:
            res = cli("sweep", _sweep(tmp_path, text), "--workers", "1", "--out", tmp_path / "out")
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, before)
        refused(res, "sweep.yaml", *words, nothing_in=tmp_path / "out")
        return
    start = time.perf_counter()
    res = cli("sweep", _sweep(tmp_path, text), "--workers", "1", "--out", tmp_path / "out")
    refused(res, "sweep.yaml", *words, nothing_in=tmp_path / "out")
    assert time.perf_counter() - start < 10


class _Hung(BaseException):
    """A sweep still checking its points after the alarm."""


SWEEP_OK = "base: base.yaml\npolicies: [adaptive]\nreplications: 2\n"


@pytest.mark.parametrize("label,out,words", [
    ("out is a file", "a_file", "a_file"),
    ("out under a file", "a_file/out", "not a directory"),
    ("out empty", "", "empty path"),
    ("report under a file", "out|a_file/r", "not a directory"),
])
def test_sweep_outputs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, label: str, out: str,
                       words: str) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a_file").write_text("mine\n")
    target, _, report = out.partition("|")
    before = tree(tmp_path)
    extra = ["--report", report] if report else []
    res = cli("sweep", _sweep(tmp_path, SWEEP_OK), "--workers", "1", "--out", target, *extra)
    refused(res, words)
    after = tree(tmp_path)
    assert after is not None and before is not None
    assert {k: v for k, v in after.items() if k not in ("sweep.yaml", "base.yaml")} == \
        {k: v for k, v in before.items() if k not in ("sweep.yaml", "base.yaml")}


def test_sweep_workers_are_bounded(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import concurrent.futures as cf

    import cell.experiments.sweep.runner as runner

    asked = []

    def pool(*args: object, max_workers: int | None = None, **kwargs: object) -> cf.Executor:
        asked.append(max_workers)
        if max_workers is not None and max_workers > 256:
            raise AssertionError(f"a pool of {max_workers} processes")
        return cf.ThreadPoolExecutor(max_workers=max_workers)

    monkeypatch.setattr(runner.cf, "ProcessPoolExecutor", pool)
    res = cli("sweep", _sweep(tmp_path, SWEEP_OK), "--workers", "100000", "--out", tmp_path / "out")
    assert res.code == 2 and len(res.err_lines) == 1 or res.code == 0 and all(a <= 256 for a in asked)


@pytest.mark.parametrize("manifest", [
    "[1, 2]", "garbage{",
])
def test_sweep_foreign_manifest(tmp_path: Path, manifest: str) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "sweep.json").write_text(manifest)
    before = tree(out)
    refused(cli("sweep", _sweep(tmp_path, SWEEP_OK), "--workers", "1", "--out", out), "sweep.json",
            nothing_in=out, before=before)


def test_sweep_resume_removes_leftovers_of_killed_runs(tmp_path: Path) -> None:
    out = tmp_path / "out"
    sweep = _sweep(tmp_path, SWEEP_OK + "batch: 1\n")
    assert cli("sweep", sweep, "--workers", "1", "--out", out).code == 0
    (out / "tasks" / ".task-00000-0000000001.csv.cell-99999999-abcdefgh.tmp").write_text("half")
    (out / "tasks" / "task-00000-0000000000.csv").unlink()
    assert cli("sweep", sweep, "--workers", "1", "--resume", "--out", out).code == 0
    assert not [p.name for p in (out / "tasks").iterdir() if p.name.endswith(".tmp")]
