"""Paths under the output writers: what is checked before any work, the directories made
for an output, syncs, and the leftovers of killed runs (:mod:`cell.plumbing.output.atomic`
writes through these)."""

from __future__ import annotations

import contextlib
import errno
import fnmatch
import os
import re
from collections.abc import Iterable, Iterator
from pathlib import Path

from cell.plumbing.errors import CellError
from cell.plumbing.errors import shown_path as _show

_UMASK = os.umask(0o022)
os.umask(_UMASK)
#: The modes an ordinary new file and directory get (0644 and 0755 under the usual umask).
FILE_MODE, DIR_MODE = 0o666 & ~_UMASK, 0o777 & ~_UMASK

_JUNK = frozenset({".DS_Store", "Thumbs.db", "desktop.ini"})  # an OS's, never the user's data
DISK_ERRORS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS, errno.EIO})


def reason(exc: OSError) -> str:  # "permission denied", "no space left on device"...
    return (exc.strerror or os.strerror(exc.errno or 0) or type(exc).__name__).lower()


@contextlib.contextmanager
def failing(what: str, only: frozenset[int] | None = None) -> Iterator[None]:
    """An OSError (with an errno in ``only``, if given) becomes a one-line CellError about ``what``."""
    try:
        yield
    except OSError as exc:
        if only is not None and exc.errno not in only:
            raise
        raise CellError(f"{what}: cannot write: {reason(exc)}") from None


def alive(pid: int) -> bool:
    """Whether process ``pid`` runs (on this host and in this PID namespace: others look dead)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return pid > 0
    return True


def absolute(target: str | os.PathLike[str], what: str, option: str = "--out") -> Path:
    """The absolute path of an output ``target`` (a file or directory: ``what``, given as
    ``option``); '' and '-' refused (a '-' would be a file of that name, not standard output)."""
    if not os.fspath(target):
        raise CellError(f"'': an empty path; name a {what}")
    if os.fspath(target) == "-":
        raise CellError(f"{option} -: no cell command writes to standard output; name a {what}")
    return Path(os.path.realpath(os.path.abspath(target)))


_TEMP_EXTRA = 27  # what a temporary name adds: .NAME.cell-tmp-PID-XXXXXXXX, .NAME.cell-PID-XXXXXXXX.tmp


def check_parent(shown: str, path: Path) -> None:
    """``path`` can be created: its nearest existing ancestor is a directory we may write in,
    and no name on the way (nor the temporary name beside it) is too long for the file system."""
    ancestor = path.parent
    while not os.path.lexists(ancestor) and ancestor != ancestor.parent:
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise CellError(f"{shown}: not a directory ({_show(ancestor)} is a file)")
    try:
        name_max, path_max = os.pathconf(ancestor, "PC_NAME_MAX"), os.pathconf(ancestor, "PC_PATH_MAX")
    except (OSError, ValueError, AttributeError):  # not every system tells
        name_max, path_max = 255, 4096
    names = [p.name for p in path.parents if ancestor in p.parents] + [path.name + "." * _TEMP_EXTRA]
    if any(len(os.fsencode(n)) > name_max for n in names) or len(os.fsencode(str(path))) + 128 > path_max:
        raise CellError(f"{shown}: file name too long (at most {name_max - _TEMP_EXTRA} bytes a name here)")
    if hasattr(os, "statvfs") and os.statvfs(ancestor).f_flag & os.ST_RDONLY:
        raise CellError(f"{shown}: cannot write in {_show(ancestor)}: read-only file system")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise CellError(f"{shown}: cannot write in {_show(ancestor)}: permission denied")


def held_to_permissions() -> bool:
    """Whether this process is held to permission bits: not root with CAP_DAC_OVERRIDE (read
    from /proc where there is one; root elsewhere is taken to override them)."""
    if os.geteuid() != 0:
        return True
    try:
        with open("/proc/self/status", encoding="ascii", errors="replace") as status:
            caps = next((x.split()[1] for x in status if x.startswith("CapEff:")), None)
    except OSError:
        return False
    return caps is not None and not int(caps, 16) & (1 << 1)  # CAP_DAC_OVERRIDE


def umask_blocks(files: bool = False) -> bool:
    """Whether the umask takes the owner's write or search permission from new folders
    (``umask 0777``: nothing could be written in a folder cell makes), or with ``files`` the
    owner's read or write permission from new files (what is written could not be read back),
    and this process is held to it."""
    return bool(_UMASK & (0o600 if files else 0o300)) and held_to_permissions()


def check_umask(shown: str, files: bool = False) -> None:
    """Refuse, before any work, an output the umask would leave unusable (:func:`umask_blocks`)."""
    if umask_blocks(files):
        what = "a file cell writes could not be read back" if files else \
            "a folder cell makes could not be written in"
        raise CellError(f"{shown}: cannot write under umask {_UMASK:04o}: {what} (umask 022 is "
                        "usual)")


def make_parents(path: Path, made: list[Path]) -> None:
    """Create the missing directories above ``path``, outermost first, each added to ``made``."""
    for parent in [p for p in path.parents if not os.path.lexists(p)][::-1]:
        os.mkdir(parent)
        made.append(parent)


def remove_made(made: list[Path]) -> None:
    for directory in reversed(made):
        with contextlib.suppress(OSError):
            os.rmdir(directory)


def fsync(path: Path, directory: bool = False) -> None:
    fd = os.open(path, os.O_RDONLY | (getattr(os, "O_DIRECTORY", 0) if directory else 0))
    try:  # some file systems cannot sync a directory: nothing more to do there
        with contextlib.suppress(*((OSError,) if directory else ())):
            os.fsync(fd)
    finally:
        os.close(fd)


def allowed(parts: list[str], names: Iterable[str], directory: bool = False) -> bool:
    """Whether the path ``parts`` is one of ``names`` (or, for a directory, holds one of them)."""
    for name in names:
        pattern = name.split("/")
        if (len(parts) < len(pattern) if directory else len(parts) == len(pattern)) and all(
                fnmatch.fnmatchcase(part, p) for part, p in zip(parts, pattern)):
            return True
    return False


_LEFTOVER = re.compile(r"\.(.+)\.[^.]+\.tmp\Z")  # a killed atomic_path's temporary file


def foreign_entries(directory: Path, names: Iterable[str], limit: int = 4) -> list[str]:
    """Up to ``limit`` entries of ``directory`` that are none of ``names`` (shown as paths): also
    one that has a name of ``names`` but is not a regular file (a directory ``parts.csv/``, a
    link, a pipe), which the command would not have written and must not replace."""
    names, found = tuple(names), list[str]()
    todo: list[tuple[Path, list[str]]] = [(directory, [])]
    while todo and len(found) < limit:
        folder, prefix = todo.pop()
        for entry in sorted(os.scandir(folder), key=lambda e: e.name):
            parts = prefix + [entry.name]
            leftover = _LEFTOVER.match(entry.name)
            if entry.is_dir(follow_symlinks=False) and allowed(parts, names, directory=True):
                todo.append((Path(entry.path), parts))
            elif entry.name in _JUNK:
                continue
            elif not (allowed(parts, names) or leftover and allowed(prefix + [leftover.group(1)], names)):
                found.append(_show("/".join(parts)))
            elif not entry.is_file(follow_symlinks=False):
                kind = "/" if entry.is_dir(follow_symlinks=False) else " (not a regular file)"
                found.append(_show("/".join(parts)) + kind)
    return found[:limit]


def sync_tree(root: Path) -> None:
    for folder, _, files in os.walk(root, topdown=False):
        for name in files:
            fsync(Path(folder, name))
        fsync(Path(folder), directory=True)


def check_file(target: str | os.PathLike[str], option: str = "--out") -> Path:
    """Refuse, changing nothing, a single-file ``target`` (given as ``option``) that cannot be
    written; its absolute path."""
    shown, path = _show(target), absolute(target, "file", option)
    if os.path.isdir(path):
        raise CellError(f"{shown}: is a directory; name a file")
    check_parent(shown, path)
    check_umask(shown, files=True)
    if not os.path.isdir(path.parent):  # folders to make
        check_umask(shown)
    return path


def clean_stale_files(path: Path) -> None:
    """Remove ``.NAME.cell-PID-XXXX.tmp`` of dead processes (and ``.NAME.XXXXXXXX.tmp`` of old
    versions, and the ``.NAME.cell-PID-XXXX.tmp.SUFFIX`` their animations staged beside it)."""
    name, suffix = re.escape(path.name), re.escape(path.suffix)
    pattern = re.compile(rf"\.{name}\.(?:cell-(\d+)-.+\.tmp(?:{suffix})?|[a-z0-9_]{{8}}\.tmp)\Z")
    with contextlib.suppress(OSError):
        for entry in os.scandir(path.parent):
            match = pattern.match(entry.name)
            if match and not (match.group(1) and alive(int(match.group(1)))):
                with contextlib.suppress(OSError):
                    os.unlink(entry.path)
