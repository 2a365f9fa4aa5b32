"""What the user sees of a command's failures and warnings (:mod:`cell.cli.main` prints it):
the one error line of each anticipated failure (bad input, an output that cannot be written,
memory, recursion, open files, an operating system's refusal to write), the outputs checked
before any work, and which warnings are shown."""

from __future__ import annotations

import argparse
import errno
import os
import sys
import warnings

try:  # imported now: when the open files run out, importing it would fail too
    import resource
except ImportError:  # pragma: no cover - not on Windows
    resource = None  # type: ignore[assignment]

from cell.plumbing.errors import CellError, ScenarioError, shown_path

#: Errors of the operating system that a command's output can meet however well it checks.
OUTPUT_ERRNOS = frozenset({errno.EACCES, errno.EPERM, errno.EROFS, errno.ENOSPC, errno.EDQUOT,
                           errno.EFBIG, errno.ENAMETOOLONG, errno.ENOTDIR, errno.EISDIR,
                           errno.ELOOP, errno.EIO, errno.EXDEV})

#: What to make smaller when a command runs out of memory.
MEMORY_HINTS = {
    "run": "run.parts", "sweep": "the grid, replications or run.parts",
    "mintime": "mintime.grid_points", "figures": "run.parts",
    "animate": "--parts or --dpi", "fit": "the trace", "path": "path.moves",
}


def outputs(args: argparse.Namespace) -> str:
    """The outputs a command was asked to write, to name when the system refuses a write."""
    given = [str(v) for v in (getattr(args, k, None) for k in ("out", "report", "figure")) if v]
    return " or ".join(given) or "the output"


def memory() -> str:
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):  # not every system tells
        return ""
    return f" (this machine has {total / 2**30:.0f} GiB)"


def open_files() -> str:
    """The open-file limit, and what to do about it, as the error says it."""
    try:
        soft = resource.getrlimit(resource.RLIMIT_NOFILE)[0]
    except (AttributeError, OSError, ValueError):  # not on this system
        return ""
    return f" (this process may open {soft}: raise it with ulimit -n, or use fewer --workers)"


#: Warnings Python's default filters show only when the program's own code raised them
#: (``__main__``): a library's deprecations, and what compiling a library's source on its first
#: import says of it (``invalid escape sequence``, once after an install: the Makefile installs
#: without compiling), are for its maintainers; the user can do nothing about them.
OWN_CODE_ONLY = (DeprecationWarning, PendingDeprecationWarning, ImportWarning, SyntaxWarning)
#: cell's own source: a warning attributed to a file in it is the program's own.
OWN_SOURCE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def shown(w: warnings.WarningMessage) -> bool:
    """Whether a warning the command met is said: as Python's default filters would (those of
    :data:`OWN_CODE_ONLY` only if attributed to cell's own code), never a ResourceWarning."""
    if issubclass(w.category, ResourceWarning):
        return False
    if not issubclass(w.category, OWN_CODE_ONLY):
        return True
    where = os.path.abspath(str(w.filename or ""))
    return where.startswith(OWN_SOURCE + os.sep)


#: Output options, checked before any work (:func:`check_targets`).
TARGETS = ("out", "report", "figure")
#: The kernel's own file systems: nothing of a command's goes there.
SYSTEM_DIRS = ("/proc", "/sys")


def check_targets(args: argparse.Namespace) -> None:
    """Every output a command was given, refused before any work if it cannot be right: an
    empty path, one under /proc or /sys, a sweep's ``--report`` inside its results folder."""
    given = {name: getattr(args, name, None) for name in TARGETS}
    for name, value in given.items():
        if value is None:
            continue
        text = os.fspath(value)
        if not text.strip():
            raise CellError(f"--{name} {text!r}: an empty path: name a file or folder")
        real = os.path.realpath(text)
        for system in SYSTEM_DIRS:
            if real == system or real.startswith(system + os.sep):
                raise CellError(f"--{name} {shown_path(text)}: under {system}, the kernel's "
                                "own file system: choose another place")
    out, report = given["out"], given["report"]
    if out is not None and report is not None and args.command == "sweep":
        o, r = os.path.realpath(out), os.path.realpath(report)
        if r.startswith(o.rstrip(os.sep) + os.sep):  # (--report DIR = --out: NAME/ in it)
            raise CellError(f"--report {shown_path(report)}: inside the results folder "
                            f"--out {shown_path(out)}, whose files are the sweep's: "
                            "choose another place")


def failure_line(exc: BaseException, args: argparse.Namespace) -> str | None:
    """The error line of an anticipated failure of the command ``args`` ran; None for a bug
    (to keep its traceback)."""
    if isinstance(exc, ScenarioError):  # found after loading (assembling the cell): still --set's
        sets = [pair.partition("=")[0].strip() for pair in getattr(args, "sets", None) or ()]
        return str(exc.given_with_set(sets))
    if isinstance(exc, CellError):
        return str(exc)
    if isinstance(exc, MemoryError):
        hint = MEMORY_HINTS.get(args.command)
        return (f"cell {args.command}: ran out of memory{memory()}"
                + (f"; try a smaller {hint}" if hint else ""))
    if isinstance(exc, RecursionError):
        return (f"cell {args.command}: input nested too deeply to process "
                f"(Python's recursion limit, {sys.getrecursionlimit():,} levels)")
    if not isinstance(exc, OSError):
        return None
    if exc.errno in (errno.EMFILE, errno.ENFILE):
        return f"cell {args.command}: too many open files{open_files()}"
    if exc.errno not in OUTPUT_ERRNOS:
        return None
    reason = (exc.strerror or os.strerror(exc.errno or 0)).lower()
    if exc.filename is None:
        return f"{outputs(args)}: cannot write: {reason}"
    return f"{shown_path(exc.filename)}: {reason}"
