"""Single files, or a few files in any directories, written whole and together or not at all.

Each target gets a temporary file beside it (``.NAME.cell-PID-XXXXXXXX.tmp``); when the caller
has written them all, they are synced and renamed over their targets in turn.  If a rename
fails, the targets already replaced get their old files back (kept as hard links
``.NAME.cell-PID-old-XXXXXXXX.tmp`` until the set is complete), or are removed if new: the
old set or the new one is there, never half of each.  SIGINT, SIGTERM and SIGHUP (Ctrl-C,
kill) wait until the renames are done (in the main thread).  Only a kill -9 or a power cut
between two renames can leave the new file of one target beside the old one of another; a
later write of a target removes the leftovers of such a run.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import tempfile
import threading
from collections.abc import Iterator
from pathlib import Path

from cell.plumbing.errors import shown_path as _show
from cell.plumbing.output.paths import (
    DISK_ERRORS,
    FILE_MODE,
    check_file,
    clean_stale_files,
    failing,
    fsync,
    make_parents,
    remove_made,
)

#: Signals held back while a set's renames run (those this system has).
_HELD = frozenset(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name))


@contextlib.contextmanager
def atomic_paths(*targets: str | os.PathLike[str]) -> Iterator[tuple[Path, ...]]:
    """Yield one temporary path per target; on success they replace the targets together,
    on error they are removed and every target stays as it was.

    The targets are checked first (:func:`~cell.plumbing.output.paths.check_file`); failing to write
    one, or a full disk while the caller writes, is a one-line :class:`~cell.plumbing.errors.CellError`.
    """
    paths, shown = [check_file(t) for t in targets], [_show(t) for t in targets]
    if len(set(paths)) < len(paths):
        raise ValueError(f"the same file twice among {shown}")
    made: list[Path] = []
    tmps: list[Path] = []
    try:
        for path, name in zip(paths, shown):
            with failing(name):
                make_parents(path, made)
                clean_stale_files(path)
                fd, temp_name = tempfile.mkstemp(prefix=f".{path.name}.cell-{os.getpid()}-", suffix=".tmp",
                                                 dir=path.parent)
                os.close(fd)
                tmps.append(Path(temp_name))
        with failing(" and ".join(shown), DISK_ERRORS):
            yield tuple(tmps)
        for tmp, name in zip(tmps, shown):
            with failing(name):
                os.chmod(tmp, FILE_MODE)  # mkstemp makes 0600; outputs are for everyone to read
                fsync(tmp)
        with _held():
            _publish(list(zip(tmps, paths, shown)))
        for parent in dict.fromkeys(p.parent for p in paths):
            with contextlib.suppress(OSError):
                fsync(parent, directory=True)
    finally:  # after success there are no tmps, and the directories made are not empty
        for tmp in tmps:
            tmp.unlink(missing_ok=True)
        remove_made(made)


def _publish(moves: list[tuple[Path, Path, str]]) -> None:
    """Rename each temporary file over its target; if one fails, put the replaced ones back."""
    done: list[tuple[Path, Path | None]] = []
    try:
        for i, (tmp, path, name) in enumerate(moves):
            with failing(name):
                old = _keep_old(tmp, path) if i < len(moves) - 1 else None  # the last needs no undo
                try:
                    os.replace(tmp, path)
                except BaseException:
                    if old is not None:
                        old.unlink(missing_ok=True)
                    raise
            done.append((path, old))
    except BaseException:
        for path, old in reversed(done):
            with contextlib.suppress(OSError):
                if old is None:
                    path.unlink()
                else:
                    os.replace(old, path)
        raise
    for _, old in done:
        if old is not None:
            with contextlib.suppress(OSError):
                old.unlink()


def _keep_old(tmp: Path, path: Path) -> Path | None:
    """A second name for the file at ``path`` (None if there is none), to put it back with."""
    if not os.path.lexists(path):
        return None
    old = tmp.with_name(tmp.name.replace(f".cell-{os.getpid()}-", f".cell-{os.getpid()}-old-", 1))
    try:
        os.link(path, old)
    except OSError:  # a file system without hard links
        shutil.copy2(path, old)
    return old


@contextlib.contextmanager
def _held() -> Iterator[None]:
    """SIGINT, SIGTERM and SIGHUP that come during the block take effect when it is left.

    Python runs signal handlers in the main thread only, so elsewhere nothing is held."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    previous = {number: signal.signal(number, lambda n, _: caught.append(n)) for number in _HELD}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, signal.SIG_DFL if handler is None else handler)
        for number in dict.fromkeys(caught):
            signal.raise_signal(number)
