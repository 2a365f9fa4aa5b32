"""Output written whole or not at all, checked before any work is done.

A set of files goes through :class:`OutputDir` (a stage beside the target directory that
replaces it as a unit), a single file through :func:`atomic_path` (a temporary file renamed
over it), a few files in any directories together through :func:`atomic_paths`.  All check up
front that the output can be written and clean up after killed runs.  Files and directories
are fsync'ed before the rename that publishes them, the parent after it: after a power cut
too, the old output or the new one is there, never empty files.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import os
import re
import shutil
import stat
import sys
import tempfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from types import TracebackType
from typing import IO, TYPE_CHECKING, Any

from cell.plumbing.errors import CellError
from cell.plumbing.errors import shown_path as _show
from cell.plumbing.output.files import atomic_paths
from cell.plumbing.output.paths import (
    DIR_MODE,
    DISK_ERRORS,
    absolute,
    alive,
    allowed,
    check_file,
    check_parent,
    check_umask,
    failing,
    foreign_entries,
    fsync,
    make_parents,
    reason,
    remove_made,
    sync_tree,
)

if TYPE_CHECKING:
    import pandas as pd

#: Digits kept in CSV floats: ten significant, identical on every run.  So an instant past
#: 1e7 s (a run of some 450,000 parts) keeps 0.01 s, past 1e8 s 0.1 s.
FLOAT_FORMAT = "%.10g"


def float_text(value: float, fmt: str = FLOAT_FORMAT) -> str:
    """A float as CSV text: ``fmt``, with ``.0`` after a whole number (``21.0``, not ``21``),
    so that pandas reads a float column as floats whatever its values."""
    text = fmt % value
    return text if "." in text or "e" in text or "n" in text else text + ".0"  # n: inf, nan


def float_formatter(fmt: str = FLOAT_FORMAT) -> Callable[[Any], str]:
    """:func:`float_text` with ``fmt``, as pandas' ``to_csv(float_format=...)`` takes it
    (pandas calls it with floats only)."""
    return lambda value: float_text(value, fmt)

_open: Any = open  # every file written goes through here (tests simulate a full disk with it)

__all__ = ["FLOAT_FORMAT", "OutputDir", "atomic_path", "atomic_paths", "check_file", "float_formatter",
           "float_text", "write_csv", "write_text"]

_renameat2: Any = None
if sys.platform.startswith("linux"):
    with contextlib.suppress(OSError, AttributeError):  # glibc >= 2.28
        _renameat2 = ctypes.CDLL(None, use_errno=True).renameat2
        _renameat2.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
        _renameat2.restype = ctypes.c_int
_AT_FDCWD, _RENAME_EXCHANGE = -100, 2


def _exchange(a: Path, b: Path) -> bool:
    """Swap the directories ``a`` and ``b`` in one step; False (nothing done) where unsupported."""
    if _renameat2 is None:
        return False
    if _renameat2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.ENOTSUP, errno.EOPNOTSUPP):
        return False
    raise OSError(code, os.strerror(code), os.fspath(b))


class OutputDir(contextlib.AbstractContextManager["OutputDir"]):
    """A directory of output files that appears whole or not at all.

    ``names``: the files the command may write, relative paths that may hold ``*`` and ``?``
    (``"fig_*.png"``, ``"tasks/*.csv"``).  Construction checks that ``target`` can be written
    and holds nothing else (a user's directory is never replaced), then creates the stage
    ``.NAME.cell-tmp-PID-XXXX`` beside it, proving the parent writable.  Leaving the ``with``
    block normally puts the stage in place of ``target`` as a unit; any exception (also
    KeyboardInterrupt) removes the stage and leaves ``target`` as it was.

    On Linux ``renameat2(RENAME_EXCHANGE)`` swaps stage and old directory: a kill at any moment
    leaves the old set or the new one.  Elsewhere the old directory is first renamed aside to
    ``.NAME.cell-old-PID-XXXX``: a kill between the two renames leaves no ``target``, and the
    next ``OutputDir`` for it puts the old set back.  Every construction also removes the
    stages of processes that no longer run (the PID is in the name).
    """

    def __init__(self, target: str | os.PathLike[str], names: Iterable[str], option: str = "--out"):
        self.target, self.names, self.option = _show(target), tuple(names), option
        self.dir = absolute(target, "directory", option)
        self._recover()
        self.check(target, self.names, option)
        self._made: list[Path] = []
        self._streams: list[IO[Any]] = []
        try:
            make_parents(self.dir, self._made)
            self.stage = Path(tempfile.mkdtemp(prefix=f".{self.dir.name}.cell-tmp-{os.getpid()}-",
                                               dir=self.dir.parent))
        except OSError as exc:
            remove_made(self._made)
            raise CellError(f"{self.target}: cannot write in {_show(self.dir.parent)}: {reason(exc)}") \
                from None

    @staticmethod
    def check(target: str | os.PathLike[str], names: Iterable[str], option: str = "--out") -> Path:
        """Refuse, changing nothing, a ``target`` this command could not write or must not replace."""
        shown, path, names = _show(target), absolute(target, "directory", option), tuple(names)
        if path == Path.cwd() or path in Path.cwd().parents:
            raise CellError(f"{shown}: holds the current directory; choose another {option}")
        check_umask(shown)
        try:
            mode = os.stat(path).st_mode
        except OSError as exc:
            check_parent(shown, path)  # a file on the way, an unwritable parent?
            if isinstance(exc, FileNotFoundError):
                return path
            raise CellError(f"{shown}: {reason(exc)}") from None
        if not stat.S_ISDIR(mode):
            raise CellError(f"{shown}: is a file, not a directory; choose another {option}")
        foreign = foreign_entries(path, names)
        if foreign:
            raise CellError(f"{shown}: holds files this command does not write ({', '.join(foreign[:3])}"
                            f"{', …' if len(foreign) > 3 else ''}); choose another {option}")
        check_parent(shown, path)
        if not os.access(path, os.W_OK | os.X_OK):
            raise CellError(f"{shown}: permission denied")
        return path

    def _recover(self) -> None:
        """Remove the stages of dead runs; put back an old set that a killed run had moved aside."""
        pattern = re.compile(rf"\.{re.escape(self.dir.name)}\.cell-(tmp|old)-(\d+)-")
        with contextlib.suppress(OSError):
            for entry in os.scandir(self.dir.parent):
                match = pattern.match(entry.name)
                if not match or alive(int(match.group(2))):
                    continue
                with contextlib.suppress(OSError):
                    if match.group(1) == "old" and not os.path.lexists(self.dir):
                        os.rename(entry.path, self.dir)
                    else:
                        shutil.rmtree(entry.path)

    def path(self, name: str) -> Path:
        """Where to write the file ``name`` (one of ``names``) in the stage."""
        parts = name.split("/")
        if any(p in ("", ".", "..") for p in parts) or not allowed(parts, self.names):
            raise ValueError(f"{name!r} is not among the files this OutputDir writes: {self.names}")
        if len(parts) > 1:
            with failing(f"{self.target}/{name}"):
                (self.stage / name).parent.mkdir(parents=True, exist_ok=True)
        return self.stage / name

    def open(self, name: str, mode: str = "w", **kwargs: Any) -> Any:  # TextIO or BinaryIO, by mode
        """The file ``name`` opened for writing (``"w"``, ``"wb"``...) in the stage; text is UTF-8."""
        if "r" in mode or "+" in mode:
            raise ValueError(f"mode {mode!r}: OutputDir files are opened for writing")
        path, text = self.path(name), {} if "b" in mode else {"encoding": "utf-8"}
        with failing(f"{self.target}/{name}"):
            self._streams.append(_open(path, mode, **text, **kwargs))  # closed at the end if not before
        return self._streams[-1]

    def write_text(self, name: str, text: str) -> None:
        with failing(f"{self.target}/{name}"), self.open(name, "w", newline="") as stream:
            stream.write(text)

    def write_csv(self, name: str, frame: pd.DataFrame, float_format: str = FLOAT_FORMAT) -> None:
        """A DataFrame as CSV with a fixed float format (byte-identical reruns)."""
        with failing(f"{self.target}/{name}"), self.open(name, "w", newline="") as stream:
            frame.to_csv(stream, index=False, float_format=float_formatter(float_format),
                         lineterminator="\n")

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if kind is None:
            return self.commit()
        self.discard()
        if isinstance(exc, OSError) and exc.errno in DISK_ERRORS:
            raise CellError(f"{self.target}: cannot write: {reason(exc)}") from None

    def discard(self) -> None:
        """Remove the stage (and the parents made for it); ``target`` stays as it was."""
        for stream in self._streams:
            with contextlib.suppress(Exception):  # a full disk again: the file goes anyway
                stream.close()
        shutil.rmtree(self.stage, ignore_errors=True)
        remove_made(self._made)

    def commit(self) -> None:
        """Put the stage in place of ``target`` as a unit, then remove the old set."""
        old: Path | None = None
        try:
            with failing(self.target):
                for stream in self._streams:  # a stream the caller left open is flushed now
                    stream.close()
                sync_tree(self.stage)
                try:
                    mode = os.lstat(self.dir).st_mode
                except FileNotFoundError:
                    os.chmod(self.stage, DIR_MODE)
                    os.rename(self.stage, self.dir)
                else:
                    foreign = foreign_entries(self.dir, self.names) if stat.S_ISDIR(mode) else ["is a file"]
                    if foreign:  # changed since the check, while the command ran
                        raise CellError(f"{self.target}: changed while cell ran ({foreign[0]}); "
                                        f"nothing written; choose another {self.option}")
                    os.chmod(self.stage, stat.S_IMODE(mode))
                    old = self._swap()
        except BaseException:
            self.discard()
            raise
        with contextlib.suppress(OSError):
            fsync(self.dir.parent, directory=True)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)

    def _swap(self) -> Path:
        """Stage in, old set out; return where the old set now is."""
        if _exchange(self.stage, self.dir):
            return self.stage
        old = self.stage.with_name(self.stage.name.replace(".cell-tmp-", ".cell-old-"))
        os.rename(self.dir, old)
        try:
            os.rename(self.stage, self.dir)
        except BaseException:
            os.rename(old, self.dir)
            raise
        return old


@contextlib.contextmanager
def atomic_path(target: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path; on success it replaces ``target``, on error it is removed.

    ``target`` is checked first (:func:`check_file`); failing to write it, or a full disk while
    the caller writes, is a one-line :class:`CellError`; temporary files of killed runs are removed.
    Several files that belong together: :func:`~cell.plumbing.output.files.atomic_paths`.
    """
    with atomic_paths(target) as (tmp,):
        yield tmp


def write_text(text: str, target: str | os.PathLike[str]) -> None:
    with atomic_path(target) as tmp, _open(tmp, "w", encoding="utf-8", newline="") as stream:
        stream.write(text)


def write_csv(frame: pd.DataFrame, target: str | os.PathLike[str], float_format: str = FLOAT_FORMAT) -> None:
    """A DataFrame as CSV, atomically, with a fixed float format (byte-identical reruns)."""
    with atomic_path(target) as tmp, _open(tmp, "w", encoding="utf-8", newline="") as stream:
        frame.to_csv(stream, index=False, float_format=float_formatter(float_format),
                     lineterminator="\n")
