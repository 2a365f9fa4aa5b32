"""Values the schema's types and bounds allow but the cell's physics does not, and sweeps.

Each case states what the promise requires; those that fail today because of code in files
this suite's owner does not edit are marked ``xfail(strict=True)`` with the file and the
fix, so that they turn into failures to remove the marker from once fixed.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest
from harness import COUNT, cli, ran_sanely, refused, tree

ROOT = Path(__file__).resolve().parents[2]


def _hole(reason: str) -> pytest.MarkDecorator:
    return pytest.mark.xfail(strict=True, reason=reason)


def _id(case: object) -> str:
    return str(case.values[0] if hasattr(case, "values") else case[0])  # type: ignore[index]


def _trace(tmp: Path, values: list[str]) -> Path:
    path = tmp / "trace.csv"
    path.write_text("interarrival_s\n" + "\n".join(values) + "\n")
    return path


#: (id, --set values, words the refusal must hold); a trace file is written when a value says {trace:...}
REFUSE = [
    ("heavy part", ["part.weight_oz=30"], ("part.weight_oz", "27.43 oz")),
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
    ("not a distribution", ["arrivals.distribution=rv_continuous"], ("arrivals.distribution",)),
    ("bogus distribution beside a trace", ["arrivals.distribution=bogus", "arrivals.trace_csv={trace:22}"],
     ("arrivals.distribution",)),
    ("trace value True", ["arrivals.trace_csv={trace:True}"], ("arrivals.trace_csv", "True")),
    ("trace value 0", ["arrivals.trace_csv={trace:0}"], ("arrivals.trace_csv",)),
    ("trace value nan", ["arrivals.trace_csv={trace:nan}"], ("arrivals.trace_csv",)),
    ("trace value -inf", ["arrivals.trace_csv={trace:-inf}"], ("arrivals.trace_csv",)),
    ("trace missing", ["arrivals.trace_csv=nowhere.csv"], ("arrivals.trace_csv", "no such file")),
    ("trace is a directory", ["arrivals.trace_csv=."], ("arrivals.trace_csv",)),
    ("minimum-time without any bound", ["robot.timing=minimum-time", "mintime.dynamics_file=null",
                                         "mintime.acceleration_bounds=false"], ("minimum-time",)),
    ("minimum-time, dynamics file missing", ["robot.timing=minimum-time", "mintime.dynamics_file=no.yaml"],
     ("mintime.dynamics_file", "no such file")),
    pytest.param("minimum-time, planner too slow",
                 ["robot.timing=minimum-time", "mintime.rate_fraction=1e-9"],
                 ("mintime.rate_fraction",), marks=_hole(
                     "cell/assembly.py robot_timing: R II planned at 3.9e9 s and R IV at 7.5e9 s (beyond the "
                     "schema's 1e6 s bound on times) are accepted with a utilisation warning, the cycle set "
                     "to 1.1e10 s; refuse a regime time above 1e6 s naming mintime.rate_fraction, as cell "
                     "mintime does")),
    ("arrivals 1e300 s apart", ["arrivals.params={c: 4.9, loc: 1e300, scale: 5.4}"], ("arrivals.params",)),
    ("arrivals 1e9 s apart", ["arrivals.params={c: 4.9, loc: 1e9, scale: 5.4}"], ("arrivals.params",)),
    ("trace value 1e308", ["arrivals.trace_csv={trace:1e308}"], ("arrivals.trace_csv", "row 2")),
    ("trace value 2e6", ["arrivals.trace_csv={trace:2e6}"], ("arrivals.trace_csv", "row 2")),
    pytest.param("spacing smaller than a part", ["belts.spacing_in=1.0"], ("belts.spacing_in",),
                 marks=_hole("cell/scenario.py _cross_checks: parts 2 in long set down 1 in apart overlap on "
                             "the output belt; refuse spacing_in - spacing_tol_in below part.size_in")),
    pytest.param("tolerance wider than the spacing", ["belts.spacing_tol_in=250"], ("belts.spacing_tol_in",),
                 marks=_hole("cell/scenario.py _cross_checks: 45 ± 250 in accepts parts on top of each "
                             "other; refuse a tolerance that lets parts overlap")),
    pytest.param("base motor too coarse for the path",
                 ["robot.motors.steps_per_rad=[1e-9, 1125, 672, 241, 241]"],
                 ("robot.motors.steps_per_rad",), marks=_hole(
                     "cell/assembly.py / cell/steptable.py: R IV's 180 degrees of base turn round to 0 "
                     "steps, so R IV takes 0.93 s instead of 9.99 s; refuse a motor that cannot resolve a "
                     "regime")),
    pytest.param("a heavier part", ["part.weight_oz=8"], ("part.weight_oz",), marks=_hole(
        "cell/assembly.py constants: refused as 'belts.output_nominal_in_s = 2.0: the robot can follow the "
        "output belt down to TD at no more than 1.9496 in/s', without naming part.weight_oz, the value "
        "that was changed and slowed the loaded motors")),
    pytest.param("LO at B", ["path.lo_from_bot_in=1e-300"], ("path.lo_from_bot_in",), marks=_hole(
        "cell/path.py / cell/assembly.py: the spline from B to LO overshoots to z = -1e300 (numpy warns "
        "of overflows) and the error quotes that coordinate with 300 digits; refuse LO closer to B than "
        "the path can bend")),
    pytest.param("B on F", ["path.bot_in=[-8.0, 0.0, 3.0]"], ("path.bot_in",), marks=_hole(
        "cell/scenario.py _cross_checks: the error blames path.lo_from_bot_in ('must lie inside the input "
        "window B-F (0 in)') and does not name path.bot_in or path.f_in, the keys that collapse the window")),
    pytest.param("drives too weak for the rates",
                 ["robot.timing=minimum-time", "robot.motors.max_rate_no_load_rad_s=[1e9, 1, 1, 3, 3]"],
                 ("robot.motors.max_rate_no_load_rad_s",), marks=_hole(
                     "cell/assembly.py robot_timing: blames 'microbot_dynamics.yaml: "
                     "drives.viscous_nm_s_rad[0] = None' for friction at the no-load rate; name "
                     "robot.motors.max_rate_no_load_rad_s and its value (as cell mintime does)")),
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
    ["controller.policy=non-adaptive", "controller.ideal_cycle_s=2.25872e1"],
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


# --- sweeps ------------------------------------------------------------------------------------

def _sweep(tmp: Path, text: str) -> Path:
    (tmp / "base.yaml").write_text("run: {parts: 4}\n")
    path = tmp / "sweep.yaml"
    path.write_text(text)
    return path


SWEEP_REFUSE = [
    ("no base", "replications: 2\n", ("base",)),
    pytest.param("base missing", "base: nowhere.yaml\nreplications: 2\n", ("nowhere.yaml",), marks=_hole(
        "cell/sweep/spec.py load_sweep: a missing base is named, but not the sweep file nor its key 'base' "
        "(the line reads 'nowhere.yaml: (file) = ...: no such scenario file')")),
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
    pytest.param("a million points", "base: base.yaml\nreplications: 2\ngrid:\n" + "".join(
        f"  {k}: [{', '.join(str(v) for v in vs)}]\n" for k, vs in (
            ("run.parts", range(1, 101)), ("belts.spacing_tol_in", [i / 10 for i in range(1, 101)]),
            ("belts.spacing_in", range(40, 140)))), ("grid",), marks=_hole(
        "cell/sweep/spec.py load_sweep: a 100 x 100 x 100 grid is assembled point by point for minutes "
        "before anything is said; refuse a grid beyond a stated number of points at once (within seconds)")),
    pytest.param("10^8 replications", "base: base.yaml\nreplications: 100000000\n", ("replications",),
                 marks=_hole("cell/sweep: 10^8 replications: every seed spawned up front (minutes, "
                             "gigabytes); refuse beyond a stated bound within seconds")),
]


@pytest.mark.parametrize("label,text,words", SWEEP_REFUSE,
                         ids=[_id(c) for c in SWEEP_REFUSE])
def test_sweep_refused(tmp_path: Path, label: str, text: str, words: tuple[str, ...]) -> None:
    """Refused in one line naming the sweep file and the key, quickly, nothing written."""
    if label in ("a million points", "10^8 replications"):  # a hang must not stall the suite
        COUNT["subprocess"] += 1
        env = {**os.environ, "PYTHONPATH": str(ROOT)}
        proc = subprocess.run([sys.executable, "-m", "cell", "sweep", str(_sweep(tmp_path, text)),
                               "--workers", "1", "--out", str(tmp_path / "out")],
                              capture_output=True, text=True, cwd=tmp_path, env=env, timeout=6)
        lines = proc.stderr.splitlines()
        assert proc.returncode == 2 and len(lines) == 1 and all(w in lines[0] for w in words), proc.stderr
        return
    start = time.perf_counter()
    res = cli("sweep", _sweep(tmp_path, text), "--workers", "1", "--out", tmp_path / "out")
    refused(res, "sweep.yaml", *words, nothing_in=tmp_path / "out")
    assert time.perf_counter() - start < 10


SWEEP_OK = "base: base.yaml\npolicies: [adaptive]\nreplications: 2\n"


@pytest.mark.parametrize("label,out,words", [
    ("out is a file", "a_file", "a_file"),
    ("out under a file", "a_file/out", "not a directory"),
    pytest.param("out empty", "", "empty path", marks=_hole(
        "cell/commands/sweep.py, cell/sweep/runner.py: --out '' writes replications.csv, sweep.json and "
        "tasks/ into the current directory and exits 0; refuse it as cell run does (OutputDir)")),
    pytest.param("report under a file", "out|a_file/r", "not a directory", marks=_hole(
        "cell/commands/sweep.py: an unwritable --report is found only after every replication has run, "
        "and the progress bar leaves a second line on stderr; check --report before any work")),
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


@_hole("cell/sweep/runner.py: with more --workers than the machine can hold (100,000 here) the runner "
       "starts them all (the machine runs out of processes and memory); bound the pool (by the tasks "
       "and the cores) or refuse the option")
def test_sweep_workers_are_bounded(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import concurrent.futures as cf

    import cell.sweep.runner as runner

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
    pytest.param("[1, 2]", marks=_hole("cell/sweep/runner.py: a sweep.json that is not cell's manifest (a "
                                       "JSON list) is overwritten silently; refuse a --out holding it")),
    pytest.param("garbage{", marks=_hole("cell/sweep/runner.py: a sweep.json that is not JSON is overwritten "
                                         "silently; refuse a --out holding it")),
])
def test_sweep_foreign_manifest(tmp_path: Path, manifest: str) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "sweep.json").write_text(manifest)
    before = tree(out)
    refused(cli("sweep", _sweep(tmp_path, SWEEP_OK), "--workers", "1", "--out", out), "sweep.json",
            nothing_in=out, before=before)


@_hole("cell/sweep/runner.py: --resume leaves the temporary files (.task-N.csv.cell-PID-*.tmp) of a killed "
       "run's other tasks in OUT/tasks forever; remove those of dead processes when a run starts")
def test_sweep_resume_removes_leftovers_of_killed_runs(tmp_path: Path) -> None:
    out = tmp_path / "out"
    sweep = _sweep(tmp_path, SWEEP_OK + "batch: 1\n")
    assert cli("sweep", sweep, "--workers", "1", "--out", out).code == 0
    (out / "tasks" / ".task-00001.csv.cell-99999999-abcdefgh.tmp").write_text("half")
    (out / "tasks" / "task-00000.csv").unlink()
    assert cli("sweep", sweep, "--workers", "1", "--resume", "--out", out).code == 0
    assert not [p.name for p in (out / "tasks").iterdir() if p.name.endswith(".tmp")]
