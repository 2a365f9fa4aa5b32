"""A sweep's ``--out`` directory: refused before any work if unusable, its manifest
(``sweep.json``, the sweep's fingerprint for ``--resume``) and its ``tasks/`` folder."""

from __future__ import annotations

import contextlib
import json
import os
import socket
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from cell.experiments.sweep.options import show
from cell.experiments.sweep.spec import Sweep
from cell.plumbing.errors import CellError
from cell.plumbing.output.atomic import write_text
from cell.plumbing.output.paths import absolute

MANIFEST = "sweep.json"
TASK_DIR = "tasks"
#: A finished task's file (:attr:`cell.experiments.sweep.spec.Task.filename`).
TASK_FILES = "task-*.csv"
#: The lock a running sweep holds in its folder (:func:`lock`).
LOCK = ".sweep.lock"
#: The manifest's fingerprint of all but the replications (:meth:`Sweep.fingerprint`): a
#: sweep that differs only in its count may reuse the folder's tasks (:func:`check_owner`).
ANY_COUNT = "fingerprint_any_replications"
#: The manifest's most replications of a point that the folder's tasks may hold.
MOST = "replications_run_most"


#: A sweep's result file, by ``cell sweep --format``: one of them, never both.
RESULT_FILES = {"csv": "replications.csv", "parquet": "replications.parquet"}


def _results(out: Path) -> list[str]:
    """The result files (:data:`RESULT_FILES`) in ``out``."""
    return [name for name in RESULT_FILES.values() if (out / name).exists()]


def check_out(out: str | Path) -> Path:
    """Refuse, before any work, a sweep directory that cannot be used: an empty name, a
    file, a directory under a file, one holding a ``sweep.json`` that is not a sweep's, or
    one holding a ``replications.csv`` or task files but no ``sweep.json``."""
    if str(out) == "":
        raise CellError("--out '': an empty path; give a directory for the sweep's results")
    absolute(out, "directory")  # '-' is refused as every command refuses it
    path = Path(out)
    for parent in (path, *path.parents):
        if parent.exists() and not parent.is_dir():
            raise CellError(f"--out {out}: {parent} is not a directory")
    manifest = path / MANIFEST
    if manifest.exists():
        if not manifest.is_file() or not isinstance(_manifest(manifest), dict):
            raise CellError(f"--out {out}: {manifest} is not a sweep's manifest; choose another "
                            "--out")
    elif theirs := _results_without_manifest(path):
        raise CellError(f"--out {out}: holds {theirs} but no {MANIFEST}: not a sweep's results, "
                        "and a sweep would replace them; choose another --out")
    return path


def _results_without_manifest(path: Path) -> str | None:
    """What a sweep would replace in ``path`` (its ``replications.csv``, task files),
    named for the message, when there is no manifest to say a sweep wrote them."""
    found = _results(path)
    found += [str(p.relative_to(path)) for p in finished_tasks(path)[:1]]
    return ", ".join(found) or None


def finished_tasks(out: str | Path) -> list[Path]:
    """The task files a run into ``out`` has finished (what ``--resume`` reuses if intact)."""
    task_dir = Path(out) / TASK_DIR
    return sorted(task_dir.glob(TASK_FILES)) if task_dir.is_dir() else []


def _manifest(path: Path) -> Any:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, UnicodeDecodeError):
        return None


def check_owner(sweep: Sweep, out: Path, resume: bool) -> None:
    """Refuse, before any work, to run ``sweep`` into ``out`` if that would lose results:
    those of another sweep (or of this one before a file it reads changed, or written by
    another version of cell), or this sweep's finished tasks without ``resume``.  Those of
    this sweep at another whole number of replications (in the same batches) are this
    sweep's: ``resume`` reuses the tasks that fit, unless :func:`_not_resizable` says why not."""
    manifest = out / MANIFEST
    found = _manifest(manifest) if manifest.is_file() else None
    tasks = len(finished_tasks(out))
    if not isinstance(found, dict) or not (tasks or _results(out)):
        return
    flag = f"--out {out}" + (" (--resume)" if resume else "")
    if found.get("fingerprint") != sweep.fingerprint():
        if found.get(ANY_COUNT) != sweep.fingerprint(replications=False):
            raise CellError(f"{flag}: holds the results of {_whose(found, sweep)}: choose "
                            "another --out or remove it")
        was = f"this sweep's results at replications: {_count(found.get('precision'), found)}"
        if why := _not_resizable(found, sweep):
            raise CellError(f"{flag}: holds {was}, and {why}; choose another --out or remove it")
        if not resume:
            raise CellError(f"--out {out}: holds {was}: add --resume to reuse those that fit "
                            f"replications: {sweep.replications}, or remove the folder")
    if resume:
        return
    if _results(out):
        raise CellError(f"--out {out}: holds a finished run of this sweep ({tasks} tasks): add "
                        "--resume to reuse it (nothing runs again), or remove the folder")
    raise CellError(f"--out {out}: holds {tasks} finished task{'s' if tasks != 1 else ''} of "
                    "this sweep: add --resume to go on, or remove the folder")


def _count(precision: object, found: dict[str, Any]) -> str:
    """A manifest's ``replications`` as the sweep file gave it (a count, or a precision)."""
    return show(precision) if isinstance(precision, dict) else str(found.get("replications"))


def _not_resizable(found: dict[str, Any], sweep: Sweep) -> str | None:
    """Why the finished tasks of a manifest's sweep, the same as ``sweep`` but for its
    replications (:meth:`Sweep.fingerprint`), cannot be reused for ``sweep``; None if they
    can: both fixed counts in the same batches, and no finished task cut short, which
    would be overwritten by fewer replications (the cut falls on a task's end, or past
    every replication this folder has run)."""
    was, now = found.get("precision"), sweep.precision
    if was is not None or now is not None:
        now_text = show(now.as_dict()) if now else str(sweep.replications)
        return (f"--resume reuses them for other replications only when both are a whole "
                f"number (now: {now_text}; a precision's rounds cannot be resized)")
    if found.get("batch") != sweep.batch:
        return (f"they were run in batches of {found.get('batch')}, not {sweep.batch}: set "
                f"batch: {found.get('batch')} to reuse them")
    most, n, batch = _most(found), sweep.replications, sweep.batch
    if n < most and n % batch:
        first = n - n % batch
        return (f"replications: {n} would cut the finished task of replications {first}-"
                f"{min(first + batch, most) - 1} short (batch {batch}): choose a multiple of "
                f"{batch}, or {most} or more")
    return None


def _most(found: dict[str, Any]) -> int:
    """The most replications of a point whose tasks a fixed-count sweep's folder may hold
    (after a --resume at fewer, those past the count are kept)."""
    counts = [found.get(k) for k in (MOST, "replications")]
    return max((c for c in counts if isinstance(c, int)), default=0)


def _whose(found: dict[str, Any], sweep: Sweep) -> str:
    """Whose results a manifest's are, for a refusal: which file changed if it can say."""
    from cell import __version__
    from cell.experiments.sweep.inputs import changed

    name = found.get("name", "unnamed")
    edited = ", ".join(changed(found.get("inputs")))
    if edited and found.get("sweep") == sweep.source:
        return f"this sweep ({name}) as it was before {edited} changed"
    if edited:
        return f"another sweep ({name}; {edited} changed since)"
    if found.get("version", __version__) != __version__:
        return f"another sweep ({name}), written by cell {found['version']} (this is " \
               f"{__version__})"
    return f"another sweep ({name})"


@contextlib.contextmanager
def lock(out: Path) -> Iterator[None]:
    """Hold ``out``'s lock while a sweep runs into it: a second sweep into the same
    folder is refused.  A lock left by a process that is gone (on this machine) is taken
    over.  Folders it had to make are removed again if nothing was written into them."""
    made = [d for d in (out, *out.parents) if not d.exists()]
    out.mkdir(parents=True, exist_ok=True)
    path = out / LOCK
    mine = f"{os.getpid()} {socket.gethostname()}\n"
    for _ in range(2):
        try:
            fd = os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            holder = _holder(path)
            if holder is not None:
                raise CellError(f"--out {out}: another sweep is running into it ({holder}; "
                                f"its lock: {path}): wait for it, or choose another --out"
                                ) from None
            path.unlink(missing_ok=True)  # stale: its process is gone
            continue
        with os.fdopen(fd, "w", encoding="utf-8") as stream:
            stream.write(mine)
        break
    else:
        raise CellError(f"--out {out}: cannot take its lock {path}; choose another --out")
    try:
        yield
    finally:
        with contextlib.suppress(OSError):
            if path.read_text(encoding="utf-8") == mine:
                path.unlink()
        with contextlib.suppress(OSError):
            for folder in made:  # innermost first; one not empty is kept, and those above it
                folder.rmdir()


def _holder(path: Path) -> str | None:
    """Who holds a lock (``process PID on HOST``), or None if its process is gone."""
    try:
        pid_text, host = path.read_text(encoding="utf-8").split()
        pid = int(pid_text)
    except (OSError, ValueError):
        return "a lock being written" if path.exists() else None
    if host == socket.gethostname():
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return None
        except PermissionError:
            pass  # alive, another user's
    return f"process {pid} on {host}"


def prepare(sweep: Sweep, out: Path, resume: bool) -> None:
    """Check ``out`` may take this sweep's results (:func:`check_owner`), clear a fresh run's
    folder, write the manifest.  Either way the temporary files of a killed run are removed."""
    from cell import __version__
    from cell.experiments.sweep.inputs import inputs

    task_dir, manifest = out / TASK_DIR, out / MANIFEST
    check_owner(sweep, out, resume)
    for leftover in task_dir.glob(".task-*.tmp") if task_dir.is_dir() else ():
        leftover.unlink(missing_ok=True)
    found = _manifest(manifest) if resume and manifest.is_file() else None
    most, any_count = sweep.replications, sweep.fingerprint(replications=False)
    if isinstance(found, dict) and found.get(ANY_COUNT) == any_count:
        most = max(most, _most(found))  # the tasks past the count are kept, for a later one
    if not resume:  # nothing of this sweep's, nor of another's, is lost (check_owner)
        for stale in finished_tasks(out):
            stale.unlink()
        for name in RESULT_FILES.values():
            (out / name).unlink(missing_ok=True)
    doc: dict[str, Any] = {"sweep": sweep.source, "name": sweep.name,
                           "fingerprint": sweep.fingerprint(),
                           ANY_COUNT: any_count,
                           "tasks": len(sweep.points) * -(-sweep.first_round // sweep.batch),
                           "replications": sweep.replications, MOST: most,
                           "seed": sweep.seed, "batch": sweep.batch}
    if sweep.precision is not None:
        doc["precision"] = sweep.precision.as_dict()
    doc |= {"version": __version__, "inputs": inputs(sweep)}
    write_text(json.dumps(doc, indent=2) + "\n", manifest)
