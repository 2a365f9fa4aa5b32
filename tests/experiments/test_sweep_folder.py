"""A sweep's --out folder never mixes nor loses results: what --resume may reuse (the
files a sweep reads, by content, and cell's version), what a run without it refuses to
delete, the lock of a running sweep; and the sweep file's checks made before any work."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from cell.cli.main import main
from cell.experiments.sweep import load_sweep, run_sweep
from cell.experiments.sweep.checks import POLICY_MEASURES, size_note
from cell.experiments.sweep.outdir import LOCK, lock
from cell.experiments.sweep.windows import pair_apart, window_warning
from cell.plumbing.errors import CellError, ScenarioError
from cell.scenario import catalog
from cell.scenario.schema import load_scenario


def traced(tmp_path: Path) -> Path:
    """A sweep over a base scenario in a folder with a space, replaying a trace beside it."""
    folder = tmp_path / "base dir"
    folder.mkdir()
    (folder / "trace.csv").write_text("interarrival_s\n" + "21.0\n" * 30)
    (folder / "traced.yaml").write_text(yaml.safe_dump(
        {"name": "traced", "arrivals": {"trace_csv": "trace.csv"}, "run": {"parts": 20}}))
    path = tmp_path / "s4.yaml"
    path.write_text(yaml.safe_dump({"base": "base dir/traced.yaml",
                                    "grid": {"belts.output_nominal_in_s": [1.8, 2.0]},
                                    "policies": ["non-adaptive", "adaptive"],
                                    "replications": 4, "batch": 2}))
    return path


def sweep_into(path: Path, out: Path, sweeps, **kwargs):
    return run_sweep(load_sweep(path), out, workers=1, replicate=sweeps.first_draw,
                     progress=False, **kwargs)


def files(folder: Path) -> dict[Path, bytes]:
    return {p: p.read_bytes() for p in folder.rglob("*") if p.is_file()}


# --------------------------------------------------------------------------- resume
@pytest.mark.parametrize("edit", ["trace", "base"])
def test_resume_after_a_file_the_sweep_reads_changed_is_refused_naming_it(sweeps, tmp_path,
                                                                          monkeypatch, edit):
    monkeypatch.chdir(tmp_path)
    path = traced(tmp_path)
    sweep_into(path, Path("o"), sweeps)
    if edit == "trace":
        (tmp_path / "base dir" / "trace.csv").write_text("interarrival_s\n5.0\n" + "21.0\n" * 29)
        name = "base dir/trace.csv"
    else:
        base = tmp_path / "base dir" / "traced.yaml"
        base.write_text(base.read_text().replace("parts: 20", "parts: 30"))
        name = "base dir/traced.yaml"
    before = files(tmp_path / "o")
    with pytest.raises(CellError) as refused:
        sweep_into(path, Path("o"), sweeps, resume=True)
    message = str(refused.value)  # the folder, the sweep, the file that changed, the way out
    assert message.startswith("--out o (--resume): ") and "(s4)" in message
    assert f" {name} changed" in message and "another --out" in message
    assert files(tmp_path / "o") == before


def test_the_fingerprint_covers_the_trace_content_and_the_version(tmp_path, monkeypatch):
    path = traced(tmp_path)
    first = load_sweep(path).fingerprint()
    assert load_sweep(path).fingerprint() == first  # the same files: the same sweep
    monkeypatch.setattr("cell.__version__", "9.9.9")
    assert load_sweep(path).fingerprint() != first
    monkeypatch.undo()
    (tmp_path / "base dir" / "trace.csv").write_text("interarrival_s\n" + "22.0\n" * 30)
    assert load_sweep(path).fingerprint() != first


def test_the_dynamics_file_is_part_of_the_fingerprint(sweeps, tmp_path):
    model = tmp_path / "model.yaml"
    model.write_bytes(catalog.path("microbot_dynamics.yaml").read_bytes())
    path = sweeps.write(tmp_path, set={"run.parts": 20,
                                       "mintime.dynamics_file": str(model)})
    first = load_sweep(path).fingerprint()
    model.write_bytes(model.read_bytes() + b"\n# edited\n")
    assert load_sweep(path).fingerprint() != first


def test_resume_after_an_upgrade_names_both_versions(sweeps, tmp_path, monkeypatch):
    path = sweeps.write(tmp_path)
    sweep_into(path, tmp_path / "o", sweeps)
    monkeypatch.setattr("cell.__version__", "9.9.9")
    with pytest.raises(CellError, match=r"holds the results of another sweep \(sweep\), "
                                        r"written by cell 0\.1\.0 \(this is 9\.9\.9\)"):
        sweep_into(path, tmp_path / "o", sweeps, resume=True)


# --------------------------------------------------------------------------- without --resume
def test_another_sweeps_results_are_refused_and_kept(sweeps, tmp_path, capsys):
    sweep_into(sweeps.write(tmp_path, name="first"), tmp_path / "o", sweeps)
    before = files(tmp_path / "o")
    other = tmp_path / "other"
    other.mkdir()
    path = sweeps.write(other, name="second", seed=99)
    assert main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"cell: error: --out {tmp_path / 'o'}: ")
    assert "another sweep (first)" in err[0] and "another --out" in err[0]
    assert files(tmp_path / "o") == before


def test_unfinished_tasks_of_this_sweep_want_resume(sweeps, tmp_path, capsys):
    path = sweeps.write(tmp_path)
    with pytest.raises(KeyboardInterrupt):
        run_sweep(load_sweep(path), tmp_path / "o", workers=1, progress=False,
                  replicate=sweeps.Interrupt(after=4, of=sweeps.first_draw))
    before = files(tmp_path / "o")
    assert main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"cell: error: --out {tmp_path / 'o'}: ")
    assert "2 finished tasks" in err and "--resume" in err
    assert files(tmp_path / "o") == before


def test_a_manifest_without_results_is_replaced(sweeps, tmp_path):
    """A run killed before any task finished left only its manifest: nothing to lose."""
    sweep_into(sweeps.write(tmp_path), tmp_path / "o", sweeps)
    for done in [*(tmp_path / "o" / "tasks").iterdir(), tmp_path / "o" / "replications.csv"]:
        done.unlink()
    outcome = sweep_into(sweeps.write(tmp_path, seed=99), tmp_path / "o", sweeps)
    assert outcome.tasks_run == 9


# --------------------------------------------------------------------------- the lock
def test_a_second_sweep_into_a_locked_folder_is_refused(sweeps, tmp_path, capsys):
    out = tmp_path / "o"
    with lock(out):
        assert (out / LOCK).read_text().split()[0] == str(os.getpid())
        code = main(["sweep", str(sweeps.write(tmp_path)), "--out", str(out), "--workers", "1"])
        err = capsys.readouterr().err
        assert code == 2 and err.startswith(f"cell: error: --out {out}: ")
        assert "another sweep" in err and f"(process {os.getpid()} on " in err
        assert err.count("\n") == 1
    assert not out.exists()  # made for the lock, and left empty: removed


def test_a_lock_left_by_a_dead_process_is_taken_over(sweeps, tmp_path):
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    out = tmp_path / "o"
    out.mkdir()
    import socket

    (out / LOCK).write_text(f"{gone.pid} {socket.gethostname()}\n")
    with lock(out):
        assert (out / LOCK).read_text().split()[0] == str(os.getpid())
    assert not (out / LOCK).exists()


# --------------------------------------------------------------------------- checks
def test_a_key_both_set_and_varied_is_refused(sweeps, tmp_path):
    path = sweeps.write(tmp_path, set={"run.parts": 20, "belts.input_nominal_in_s": 4},
                        grid={"belts.input_nominal_in_s": [2, 3]})
    with pytest.raises(ScenarioError) as refused:
        load_sweep(path)
    error = refused.value
    assert (error.file, error.key, error.value) == (str(path), "set.belts.input_nominal_in_s", 4)
    assert "'grid'" in error.why


def test_a_key_set_and_varied_under_a_policy_is_refused(sweeps, tmp_path):
    path = sweeps.write(tmp_path, set={"run.parts": 20, "controller.ideal_cycle_s": 22.0})
    with pytest.raises(ScenarioError, match="also varied in 'policies.non-adaptive'"):
        load_sweep(path)


@pytest.mark.parametrize(("measure", "policies"), [("thesis_slack_s", ["adaptive"]),
                                                   ("ip_thesis_memoryless", ["non-adaptive"])])
def test_a_precision_measure_no_swept_policy_gives_is_refused(sweeps, tmp_path, measure,
                                                              policies):
    path = sweeps.write(tmp_path, policies=policies, replications={
        "precision": 0.05, "measure": measure, "min": 4, "max": 8})
    with pytest.raises(ScenarioError, match=f"replications.measure = '{measure}': only "
                                            ".* gives it a value, and the sweep runs "):
        load_sweep(path)
    ok = sweeps.write(tmp_path, policies=["non-adaptive", "adaptive"], replications={
        "precision": 0.05, "measure": measure, "min": 4, "max": 8})
    assert load_sweep(ok).precision.measure == measure


def test_the_policy_specific_measures_are_those_a_run_leaves_empty():
    from cell.experiments.sweep import simulate_summary

    empty = {}
    for policy in ("non-adaptive", "adaptive"):
        s = load_scenario("baseline", {"run.parts": 20, "controller.policy": policy})
        row = simulate_summary(s, np.random.SeedSequence(1))
        empty[policy] = {k for k, v in row.items() if isinstance(v, float) and math.isnan(v)}
    only = {m: tuple(p for p in empty if m not in empty[p]) for m in empty["adaptive"]
            | empty["non-adaptive"]}
    assert {m: g for m, g in only.items() if g} == POLICY_MEASURES


def test_a_large_sweep_says_its_size_first(sweeps, tmp_path):
    small = load_sweep(sweeps.write(tmp_path))
    assert size_note(small, 2) is None
    large = load_sweep(sweeps.write(tmp_path, replications=60_000))  # 3 points
    note = size_note(large, 2)
    assert note.startswith("180,000 runs ") and "(3 points x 60,000 replications)" in note
    assert "hours of one core, about " in note and "with 2 workers" in note


# --------------------------------------------------------------------------- auto warm-up
def test_an_auto_warmup_is_a_different_window_on_either_side(sweeps, tmp_path):
    sweep = load_sweep(sweeps.write(tmp_path, set={"run.parts": 30,
                                                   "run.warmup_parts": "auto"}))
    pairs = sweep.pairs()
    assert pairs and all(pair_apart(sweep, p) == [("warmup_parts", "auto", "auto")]
                         for p in pairs)
    warned = window_warning(sweep)
    assert warned.startswith(f"{len(pairs)} of {len(pairs)} paired comparisons ")
    assert "(run.warmup_parts auto against auto " in warned and "MSER-5" in warned
    fixed = load_sweep(sweeps.write(tmp_path, set={"run.parts": 30, "run.warmup_parts": 4}))
    assert window_warning(fixed) is None
