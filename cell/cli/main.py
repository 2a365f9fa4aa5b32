"""The ``cell`` command: ``cell run | sweep | figures | animate | fit | ... ``.

Each subcommand is a module of :mod:`cell.cli.common` (its arguments and its
``main``).  This is the one place where failures become what the user sees:
every anticipated failure is one line on stderr and exit code 2 — bad input or
an output that cannot be written (:class:`~cell.plumbing.errors.CellError`), a usage
error, memory running out, input nested past Python's recursion limit, and an
operating-system refusal to write (permission, read-only file system, full
disk, name too long) that got past the commands' own checks.  Ctrl-C is exit
130, wherever it lands (also in an import, which may turn it into an ImportError); a
reader that leaves (``cell run ... | head``) is ignored
(:mod:`cell.plumbing.streams`).  Anything else is a bug and keeps its traceback.
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import functools
import importlib
import os
import sys
import warnings
from collections.abc import Sequence
from typing import Any, NoReturn

try:  # imported now: when the open files run out, importing it would fail too
    import resource
except ImportError:  # pragma: no cover - not on Windows
    resource = None  # type: ignore[assignment]

from cell import __version__
from cell.plumbing.errors import CellError, ScenarioError, one_line, shown_path
from cell.plumbing.interrupts import Stops, exit_now, interrupted, stopped_by

#: Subcommands in the order ``cell --help`` lists them; each is cell.cli.<name>_command.
COMMANDS = ("run", "sweep", "compare", "optimize", "sensitivity", "fit", "figures", "animate",
            "path", "mintime", "hindsight", "scenarios", "schema", "docs", "bench")

#: Errors of the operating system that a command's output can meet however well it checks.
OUTPUT_ERRNOS = frozenset({errno.EACCES, errno.EPERM, errno.EROFS, errno.ENOSPC, errno.EDQUOT,
                           errno.EFBIG, errno.ENAMETOOLONG, errno.ENOTDIR, errno.EISDIR,
                           errno.ELOOP, errno.EIO, errno.EXDEV})

#: The exit code of an interrupted command: 128 + SIGINT, as a shell reports Ctrl-C.
INTERRUPTED = 130
#: And of a killed one: 128 + SIGTERM.
TERMINATED = 143

#: The stop signals of the command running in this process (see :class:`Stops`).
_stops = Stops()

#: What to make smaller when a command runs out of memory.
MEMORY_HINTS = {
    "run": "run.parts", "sweep": "the grid, replications or run.parts",
    "mintime": "mintime.grid_points", "figures": "run.parts",
    "animate": "--parts or --dpi", "fit": "the trace", "path": "path.moves",
}


class Parser(argparse.ArgumentParser):
    """argparse with usage errors on one line (``cell: error: run: ... (see cell run --help)``)
    and no exit."""

    def error(self, message: str) -> NoReturn:
        sub = self.prog.partition(" ")[2]  # "cell run" -> "run": named once, not "cell" twice
        raise _UsageError(f"{sub + ': ' if sub else ''}{message} (see {self.prog} --help)")


class _UsageError(Exception):
    pass


def _module(name: str) -> Any:
    return importlib.import_module(f"cell.cli.{name}_command")


def build_parser() -> argparse.ArgumentParser:
    """The parser of ``cell`` and its subcommands, built once a process: building it (argparse
    and gettext's look-ups for each of the commands' options) took about 3.8 ms, and the test
    suite runs ``main`` in-process some 2,300 times (about 9 s of CPU).  Parsing leaves it
    unchanged: each ``parse_known_args`` gives a new namespace."""
    return _parser()


@functools.cache
def _parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="cell",
        description="Simulate King's (1984) robotic transfer station: what-if studies of an "
                    "adaptive robot cell.")
    parser.add_argument("--version", action="version", version=f"cell {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        module = _module(name)
        p = sub.add_parser(name, help=module.HELP, description=module.DESCRIPTION)
        module.add_arguments(p)
        SUBPARSERS[name] = p
    return parser


#: Each subcommand's parser, by name, as build_parser made it (once, with the parser): an
#: argument the subcommand does not know is its usage error, pointing to its own --help.
SUBPARSERS: dict[str, argparse.ArgumentParser] = {}


def _fail(message: str) -> int:
    if _stops.settled():  # the error came of a stop (ffmpeg, stopped first, failed)
        raise KeyboardInterrupt
    print(f"cell: error: {one_line(message, 1000)}", file=sys.stderr)
    return 2


def _outputs(args: argparse.Namespace) -> str:
    """The outputs a command was asked to write, to name when the system refuses a write."""
    given = [str(v) for v in (getattr(args, k, None) for k in ("out", "report", "figure")) if v]
    return " or ".join(given) or "the output"


def _memory() -> str:
    try:
        total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):  # not every system tells
        return ""
    return f" (this machine has {total / 2**30:.0f} GiB)"


def _open_files() -> str:
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


def _run(args: argparse.Namespace) -> int:
    """The command; a warning that a finished command met is one line each (a refused one's are
    dropped: its error says what went wrong), those Python would show (:func:`shown`).  Not a
    ResourceWarning: an unclosed file reported whenever the collector happens to free it is not
    about the command (Python hides those too), and in-process, as the tests run it, it may be
    another caller's."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        warnings.simplefilter("ignore", ResourceWarning)
        code = int(_module(args.command).main(args) or 0)
    for text in dict.fromkeys(f"{w.message} ({w.category.__name__})" for w in caught if shown(w)):
        print(f"cell: warning: {one_line(text, 300)}", file=sys.stderr)
    return code


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; the exit code (0 done, 2 refused, 130 interrupted, 143 terminated).  A
    reader of stdout or stderr that leaves (``| head``) stops neither the command nor its error
    line's exit code.

    With ``argv`` None the process is the command's: stopped, it ends at once with its code
    (:func:`cell.plumbing.interrupts.exit_now`), whatever Ctrl-C or kill met on its way."""
    global _stops
    _stops = stops = Stops().install()  # not armed yet: a stop now is remembered, raised by arm()
    made: list[str] = []  # the folder _matplotlib_home makes, named before it is made
    code = 0
    try:
        try:
            stops.arm()
            from cell.plumbing.streams import reader_may_leave, standard_streams

            standard_streams()
            _matplotlib_home(made)
            with reader_may_leave() as stdout:
                code = _where() or _main(argv, stdout)
            if stdout.failed is not None and stdout.product and code == 0:  # lost: not done
                reason = stdout.failed.strerror or os.strerror(stdout.failed.errno or 0)
                code = _fail(f"standard output: cannot write: {reason.lower()}")
            if stops.settled():  # stopped while it finished: said so, its outputs whole
                code = _said_stopped(None, stops.signum)
        finally:  # a stop before this line is raised, and caught below; after it, remembered
            stops.disarm()
    except BaseException as exc:  # a stop, or one that became another error on its way
        if not (interrupted(exc) or stops.settled()):
            raise
        code = _said_stopped(exc, stops.signum)
    finally:
        if made:  # before the handlers go back: a stop now could not leave it behind
            import shutil

            shutil.rmtree(made[0], ignore_errors=True)
            with contextlib.suppress(OSError):  # made, not yet opened to its owner (umask)
                os.rmdir(made[0])
        stops.restore()
    if stops.signum is not None and code not in (INTERRUPTED, TERMINATED):
        code = _said_stopped(None, stops.signum)  # came as the command ended: not yet said
    if code in (INTERRUPTED, TERMINATED) and argv is None:
        exit_now(code)
    return code


def _said_stopped(exc: BaseException | None, signum: int | None) -> int:
    code, line = stopped_by(exc, signum)
    with contextlib.suppress(Exception):
        print(line, file=sys.stderr)
    return code


#: Output options, checked before any work (:func:`_check_targets`).
TARGETS = ("out", "report", "figure")
#: The kernel's own file systems: nothing of a command's goes there.
SYSTEM_DIRS = ("/proc", "/sys")


def _check_targets(args: argparse.Namespace) -> None:
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


def _usable(path: str) -> bool:
    """Whether ``path`` is, or could be made as, a folder one can write in (nothing made)."""
    path = os.path.abspath(path)
    while not os.path.lexists(path):
        parent = os.path.dirname(path)
        if parent == path:
            return False
        path = parent
    return os.path.isdir(path) and os.access(path, os.W_OK | os.X_OK)


def _matplotlib_home(made: list[str]) -> None:
    """A temporary folder for matplotlib's configuration and cache, made (and put in
    ``MPLCONFIGDIR``) only when the one it would use cannot be written (a read-only or
    file-valued ``HOME``, a bad ``MPLCONFIGDIR``): matplotlib would otherwise warn on stderr
    and leave its own temporary folder behind.  Its name goes into ``made`` before the folder
    is made, so that the caller removes it at the end even if a stop cut this short."""
    given = os.environ.get("MPLCONFIGDIR")
    if given:
        wanted = given
    else:
        base = os.environ.get("XDG_CONFIG_HOME", "")
        if not os.path.isabs(base):
            base = os.path.join(os.path.expanduser("~"), ".config")
        wanted = os.path.join(base, "matplotlib")
    from cell.plumbing.output.paths import umask_blocks

    blocked = umask_blocks()  # what matplotlib would make, it could not write in
    if os.path.isabs(wanted) and _usable(wanted) and not (blocked and not os.path.isdir(wanted)):
        return
    import tempfile

    try:
        parent = tempfile.gettempdir()
    except OSError:  # no temporary folder can be written: matplotlib's own warning stands
        return
    for _ in range(100):
        made[:] = [os.path.join(parent, f"cell-matplotlib-{os.urandom(6).hex()}")]
        try:
            os.mkdir(made[0], 0o700)
        except FileExistsError:  # (not ours: never to be removed)
            made.clear()
            continue
        except OSError:
            break
        try:
            os.chmod(made[0], 0o700)  # the owner's, whatever the umask took
        except OSError:
            with contextlib.suppress(OSError):
                os.rmdir(made[0])
            break
        os.environ["MPLCONFIGDIR"] = made[0]
        return
    made.clear()


def _where() -> int:
    """0 if the working directory exists; else the error line's exit code (every relative path,
    and much of what the libraries do, needs it)."""
    try:
        os.getcwd()
    except OSError as exc:
        return _fail(f"the working directory is gone ({(exc.strerror or str(exc)).lower()}): "
                     "cd into one that exists")
    return 0


def _main(argv: Sequence[str] | None, stdout: Any = None) -> int:
    """Parse and run the command; ``stdout`` (the guarded standard output) is told whether what
    is printed is the command's product: no ``--out`` (``cell fit``, ``cell compare`` without
    it; a listing)."""
    parser = build_parser()
    try:
        args, extra = parser.parse_known_args(argv)
        if extra:
            SUBPARSERS.get(args.command, parser).error(
                "unrecognized arguments: " + " ".join(extra))
    except _UsageError as exc:  # "cell: error: run: ... (see cell run --help)"
        return _fail(str(exc))
    except SystemExit as exc:  # --help, --version: printed, done
        return exc.code if isinstance(exc.code, int) else 0
    if stdout is not None:
        stdout.product = not getattr(args, "out", None)
    try:
        _check_targets(args)
        return _run(args)
    except ScenarioError as exc:  # found after loading (assembling the cell): still --set's
        sets = [pair.partition("=")[0].strip() for pair in getattr(args, "sets", None) or ()]
        return _fail(str(exc.given_with_set(sets)))
    except CellError as exc:
        return _fail(str(exc))
    except MemoryError:
        hint = MEMORY_HINTS.get(args.command)
        return _fail(f"cell {args.command}: ran out of memory{_memory()}"
                     + (f"; try a smaller {hint}" if hint else ""))
    except RecursionError:
        return _fail(f"cell {args.command}: input nested too deeply to process "
                     f"(Python's recursion limit, {sys.getrecursionlimit():,} levels)")
    except OSError as exc:
        if exc.errno in (errno.EMFILE, errno.ENFILE):
            return _fail(f"cell {args.command}: too many open files{_open_files()}")
        if exc.errno not in OUTPUT_ERRNOS:
            raise
        reason = (exc.strerror or os.strerror(exc.errno or 0)).lower()
        if exc.filename is None:
            return _fail(f"{_outputs(args)}: cannot write: {reason}")
        return _fail(f"{shown_path(exc.filename)}: {reason}")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
