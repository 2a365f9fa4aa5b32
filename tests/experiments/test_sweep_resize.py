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
from tests.prose import in_order

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
    message = str(refused.value)  # the folder, the count it holds, the count asked, the task cut
    assert message.startswith(f"--out {tmp_path / 'o'} (--resume): ")
    assert in_order(message, f"replications: {after[0] if len(after) > 1 else before},",
                    f"replications: {n} would cut", f"replications {cut} short (batch 2)",
                    "a multiple of 2", f"or {before} or more", "another --out")
    assert folder(tmp_path / "o") == kept


def test_another_count_without_resume_is_refused_asking_for_it(sweeps, tmp_path, capsys):
    into(sweeps, tmp_path, "o", replications=4)
    kept = folder(tmp_path / "o")
    path = sweeps.write(tmp_path, replications=8)
    assert main(["sweep", str(path), "--out", str(tmp_path / "o"), "--workers", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"cell: error: --out {tmp_path / 'o'}: ")
    assert in_order(err, "replications: 4", "--resume", "replications: 8")
    assert folder(tmp_path / "o") == kept


@pytest.mark.parametrize(("then", "now", "why"), [
    ({"batch": 2}, {"batch": 4, "replications": 8},
     ("batches of 2, not 4", "batch: 2")),
    ({"replications": PRECISION}, {"replications": 8}, ("whole number", "(now: 8;")),
    ({}, {"replications": PRECISION}, ("whole number", f"(now: {SHOWN % 8};")),
    ({"replications": PRECISION}, {"replications": {**PRECISION, "max": 10}},
     ("whole number", f"(now: {SHOWN % 10};")),
])
def test_a_resize_that_is_not_only_a_count_is_refused_naming_why(sweeps, tmp_path, then, now,
                                                                 why):
    first = into(sweeps, tmp_path, "o", **then)
    kept = folder(tmp_path / "o")
    was = then.get("replications", 6)
    shown = SHOWN % 8 if isinstance(was, dict) else was
    with pytest.raises(CellError) as refused:
        into(sweeps, tmp_path, "o", resume=True, **now)
    message = str(refused.value)
    assert message.startswith(f"--out {tmp_path / 'o'} (--resume): ")
    assert in_order(message, f"replications: {shown},", *why, "another --out")
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
    message = str(refused.value)  # the folder, the sweep, the file that changed
    assert message.startswith(f"--out {tmp_path / 'o'} (--resume): ")
    assert in_order(message, "(sweep)", f"{tmp_path}/sweep.yaml changed", "another --out")
    assert folder(tmp_path / "o") == kept
