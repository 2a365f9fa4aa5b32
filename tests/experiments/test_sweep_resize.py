"""--resume at another number of replications: replication r's stream does not depend on
the count, so the finished tasks that fit are reused and the folder ends as a fresh run at
the new count would leave it; what cannot be reused safely is refused, naming why."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cell.cli.main import main
from cell.experiments.sweep import load_sweep, run_sweep
from cell.plumbing.errors import CellError

PRECISION = {"precision": 0.01, "measure": "parts_per_hr_wallclock", "min": 4, "max": 8}
SHOWN = ("{precision: 0.01, measure: parts_per_hr_wallclock, min: 4, max: %d, "
         "confidence: 0.95}")


def draw(scenario, seed) -> dict:
    """The stream's first uniform, as a measure that never reaches the precision."""
    return {"parts_per_hr_wallclock": 100.0 + 50.0 * np.random.default_rng(seed).random()}


def into(sweeps, tmp_path: Path, out: str, resume: bool = False, workers: int = 1,
         counter=None, **fields):
    """Run the test sweep (3 points, batch 2) with ``fields`` changed into ``tmp_path/out``."""
    sweep = load_sweep(sweeps.write(tmp_path, **fields))
    return run_sweep(sweep, tmp_path / out, workers=workers, resume=resume, progress=False,
                     replicate=counter or draw)


def folder(path: Path) -> dict[str, bytes]:
    return {str(p.relative_to(path)): p.read_bytes() for p in path.rglob("*") if p.is_file()}


@pytest.mark.parametrize("workers", [1, 2])
def test_more_replications_reuse_the_finished_tasks_and_end_as_a_fresh_run(sweeps, tmp_path,
                                                                           workers):
    into(sweeps, tmp_path, "o", replications=5)  # its last tasks hold replication 4 only
    fresh = into(sweeps, tmp_path, "fresh", workers=workers, replications=9)
    more = into(sweeps, tmp_path, "o", resume=True, workers=workers, replications=9)
    assert (more.tasks_reused, more.tasks_run) == (3 * 2, 3 * 3)  # 0-1, 2-3 kept; 4-5 again
    assert more.counts == fresh.counts == {0: 9, 1: 9, 2: 9}
    assert folder(tmp_path / "o") == folder(tmp_path / "fresh")  # sweep.json too


def test_only_the_new_replications_run(sweeps, tmp_path):
    into(sweeps, tmp_path, "o", replications=4)
    counter = sweeps.Interrupt(after=10**9, of=draw)
    into(sweeps, tmp_path, "o", resume=True, counter=counter, replications=10)
    assert counter.calls == 3 * 6


def test_fewer_replications_cut_on_a_task_end_reuse_what_fits_and_keep_the_rest(sweeps,
                                                                                tmp_path):
    into(sweeps, tmp_path, "o", replications=9)
    kept = folder(tmp_path / "o" / "tasks")
    fewer = into(sweeps, tmp_path, "o", resume=True, replications=4)
    assert (fewer.tasks_reused, fewer.tasks_run) == (3 * 2, 0)
    assert fewer.path.read_bytes() == into(sweeps, tmp_path, "fresh", replications=4
                                           ).path.read_bytes()
    assert folder(tmp_path / "o" / "tasks") == kept  # replications 4-8 are not thrown away
    again = into(sweeps, tmp_path, "o", resume=True, replications=9)
    assert (again.tasks_reused, again.tasks_run) == (3 * 5, 0)
    assert again.path.read_bytes() == into(sweeps, tmp_path, "fresh9", replications=9
                                           ).path.read_bytes()


@pytest.mark.parametrize(("before", "after", "cut"), [(9, [5], "4-5"), (9, [4, 7], "6-7"),
                                                      (6, [3], "2-3")])
def test_fewer_replications_that_cut_a_finished_task_short_are_refused(sweeps, tmp_path,
                                                                       before, after, cut):
    into(sweeps, tmp_path, "o", replications=before)
    for n in after[:-1]:  # a cut that fits: the tasks past it are kept, and still count
        into(sweeps, tmp_path, "o", resume=True, replications=n)
    kept, n = folder(tmp_path / "o"), after[-1]
    with pytest.raises(CellError) as refused:
        into(sweeps, tmp_path, "o", resume=True, replications=n)
    assert str(refused.value) == (
        f"--out {tmp_path / 'o'} (--resume): holds this sweep's results at replications: "
        f"{after[0] if len(after) > 1 else before}, and replications: {n} would cut the "
        f"finished task of replications {cut} short (batch 2): choose a multiple of 2, or "
        f"{before} or more; choose another --out or remove it")
    assert folder(tmp_path / "o") == kept


def test_another_count_without_resume_is_refused_asking_for_it(sweeps, tmp_path, capsys):
    into(sweeps, tmp_path, "o", replications=4)
    kept = folder(tmp_path / "o")
    path = sweeps.write(tmp_path, replications=8)
    assert main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1"]) == 2
    assert capsys.readouterr().err == (
        f"cell: error: --out {tmp_path / 'o'}: holds this sweep's results at replications: 4: "
        "add --resume to reuse those that fit replications: 8, or remove the folder\n")
    assert folder(tmp_path / "o") == kept


@pytest.mark.parametrize(("then", "now", "why"), [
    ({"batch": 2}, {"batch": 4, "replications": 8},
     "they were run in batches of 2, not 4: set batch: 2 to reuse them"),
    ({"replications": PRECISION}, {"replications": 8},
     "--resume reuses them for other replications only when both are a whole number (now: 8; "
     "a precision's rounds cannot be resized)"),
    ({}, {"replications": PRECISION},
     "--resume reuses them for other replications only when both are a whole number (now: "
     f"{SHOWN % 8}; a precision's rounds cannot be resized)"),
    ({"replications": PRECISION}, {"replications": {**PRECISION, "max": 10}},
     "--resume reuses them for other replications only when both are a whole number (now: "
     f"{SHOWN % 10}; a precision's rounds cannot be resized)"),
])
def test_a_resize_that_is_not_only_a_count_is_refused_naming_why(sweeps, tmp_path, then, now,
                                                                 why):
    first = into(sweeps, tmp_path, "o", **then)
    kept = folder(tmp_path / "o")
    was = then.get("replications", 6)
    shown = SHOWN % 8 if isinstance(was, dict) else was
    with pytest.raises(CellError) as refused:
        into(sweeps, tmp_path, "o", resume=True, **now)
    assert str(refused.value) == (f"--out {tmp_path / 'o'} (--resume): holds this sweep's "
                                  f"results at replications: {shown}, and {why}; choose "
                                  "another --out or remove it")
    assert folder(tmp_path / "o") == kept and first.tasks_run


@pytest.mark.parametrize("other", [{"seed": 8}, {"set": {"run.parts": 21}},
                                   {"policies": ["adaptive"]}])
def test_a_count_changed_with_anything_else_is_another_sweep(sweeps, tmp_path, other):
    into(sweeps, tmp_path, "o", replications=4)
    assert load_sweep(sweeps.write(tmp_path, replications=8, **other)).fingerprint(
        replications=False) != load_sweep(sweeps.write(tmp_path)).fingerprint(
        replications=False)
    kept = folder(tmp_path / "o")
    with pytest.raises(CellError) as refused:
        into(sweeps, tmp_path, "o", resume=True, replications=8, **other)
    assert str(refused.value) == (f"--out {tmp_path / 'o'} (--resume): holds the results of "
                                  f"this sweep (sweep) as it was before {tmp_path}/sweep.yaml "
                                  "changed: choose another --out or remove it")
    assert folder(tmp_path / "o") == kept
