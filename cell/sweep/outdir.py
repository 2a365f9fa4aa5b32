"""A sweep's ``--out`` directory: refused before any work if unusable, its manifest
(``sweep.json``, the sweep's fingerprint for ``--resume``) and its ``tasks/`` folder."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from cell.errors import CellError
from cell.output import write_text
from cell.sweep.spec import Sweep

MANIFEST = "sweep.json"
TASK_DIR = "tasks"
#: A finished task's file (:attr:`cell.sweep.spec.Task.filename`).
TASK_FILES = "task-*.csv"


def check_out(out: str | Path) -> Path:
    """Refuse, before any work, a sweep directory that cannot be used: an empty name, a
    file, a directory under a file, one holding a ``sweep.json`` that is not a sweep's, or
    one holding a ``replications.csv`` or task files but no ``sweep.json``."""
    if str(out) == "":
        raise CellError("--out '': an empty path; give a directory for the sweep's results")
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
    found = ["replications.csv"] if (path / "replications.csv").exists() else []
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


def prepare(sweep: Sweep, out: Path, resume: bool) -> None:
    """Check a resumed directory is this sweep's, or clear a fresh one; write the manifest.
    Either way the temporary files of a killed run are removed."""
    task_dir, manifest = out / TASK_DIR, out / MANIFEST
    fingerprint = sweep.fingerprint()
    for leftover in task_dir.glob(".task-*.tmp") if task_dir.is_dir() else ():
        leftover.unlink(missing_ok=True)
    if resume and manifest.is_file():
        found = _manifest(manifest)
        previous = found.get("fingerprint") if isinstance(found, dict) else None
        if previous != fingerprint:
            raise CellError(f"--resume: {out} holds the results of a different sweep "
                            f"(or of {sweep.source} before it was edited); "
                            "run without --resume or choose another --out")
    else:
        for stale in finished_tasks(out):
            stale.unlink()
        (out / "replications.csv").unlink(missing_ok=True)
    doc: dict[str, Any] = {"sweep": sweep.source, "name": sweep.name, "fingerprint": fingerprint,
                           "tasks": len(sweep.points) * -(-sweep.first_round // sweep.batch),
                           "replications": sweep.replications, "seed": sweep.seed,
                           "batch": sweep.batch}
    if sweep.precision is not None:
        doc["precision"] = sweep.precision.as_dict()
    write_text(json.dumps(doc, indent=2) + "\n", manifest)
