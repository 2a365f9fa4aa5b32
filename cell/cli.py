"""The ``cell`` command: ``cell run | sweep | figures | animate | fit | ... ``.

Each subcommand is a module of :mod:`cell.commands` (its arguments and its
``main``).  This is the one place where failures become what the user sees:
every anticipated failure is one line on stderr and exit code 2 — bad input or
an output that cannot be written (:class:`~cell.errors.CellError`), a usage
error, memory running out, input nested past Python's recursion limit, and an
operating-system refusal to write (permission, read-only file system, full
disk, name too long) that got past the commands' own checks.  Ctrl-C is exit
130, wherever it lands (also in an import, which may turn it into an ImportError); a
reader that leaves (``cell run ... | head``) is ignored
(:mod:`cell.streams`).  Anything else is a bug and keeps its traceback.
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import importlib
import os
import sys
import warnings
from collections.abc import Sequence
from typing import Any, NoReturn

from cell import __version__
from cell.errors import CellError, ScenarioError, one_line, shown_path
from cell.interrupts import exit_now

#: Subcommands in the order ``cell --help`` lists them; each is cell.commands.<name>.
COMMANDS = ("run", "sweep", "compare", "fit", "figures", "animate", "path", "mintime",
            "scenarios", "schema", "docs", "bench")

#: Errors of the operating system that a command's output can meet however well it checks.
OUTPUT_ERRNOS = frozenset({errno.EACCES, errno.EPERM, errno.EROFS, errno.ENOSPC, errno.EDQUOT,
                           errno.EFBIG, errno.ENAMETOOLONG, errno.ENOTDIR, errno.EISDIR,
                           errno.ELOOP, errno.EIO, errno.EXDEV})

#: The exit code of an interrupted command: 128 + SIGINT, as a shell reports Ctrl-C.
INTERRUPTED = 130

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
    return importlib.import_module(f"cell.commands.{name}")


def build_parser() -> argparse.ArgumentParser:
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


#: Each subcommand's parser, by name, as build_parser made it: an argument the subcommand
#: does not know is its usage error, pointing to its own --help.
SUBPARSERS: dict[str, argparse.ArgumentParser] = {}


def _fail(message: str) -> int:
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


def _run(args: argparse.Namespace) -> int:
    """The command; a warning that a finished command met is one line each (a refused one's are
    dropped: its error says what went wrong)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        code = int(_module(args.command).main(args) or 0)
    for text in dict.fromkeys(f"{w.message} ({w.category.__name__})" for w in caught):
        print(f"cell: warning: {one_line(text, 300)}", file=sys.stderr)
    return code


def interrupted(exc: BaseException) -> bool:
    """Whether ``exc`` is Ctrl-C or came of it: a KeyboardInterrupt, or an error raised while
    one was handled (``ImportError: initialization failed`` of a module it cut short)."""
    todo: list[BaseException | None] = [exc]
    seen: set[int] = set()
    while todo:
        e = todo.pop()
        if e is None or id(e) in seen:
            continue
        if isinstance(e, KeyboardInterrupt):
            return True
        seen.add(id(e))
        todo += [e.__cause__, e.__context__]
    return False


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; the exit code (0 done, 2 refused, 130 interrupted).  A reader of stdout
    or stderr that leaves (``| head``) stops neither the command nor its error line's exit code.

    With ``argv`` None the process is the command's: interrupted, it ends at once with 130
    (:func:`cell.interrupts.exit_now`), whatever Ctrl-C met on its way."""
    try:
        from cell.streams import reader_may_leave

        with reader_may_leave():
            code = _main(argv)
    except BaseException as exc:  # Ctrl-C while starting, or one that became another error
        if not interrupted(exc):
            raise
        with contextlib.suppress(Exception):
            print("cell: interrupted", file=sys.stderr)
        code = INTERRUPTED
    if code == INTERRUPTED and argv is None:
        exit_now(code)
    return code


def _main(argv: Sequence[str] | None) -> int:
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
    try:
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
    except KeyboardInterrupt:
        print("cell: interrupted", file=sys.stderr)
        return INTERRUPTED
    except OSError as exc:
        if exc.errno not in OUTPUT_ERRNOS:
            raise
        reason = (exc.strerror or os.strerror(exc.errno or 0)).lower()
        if exc.filename is None:
            return _fail(f"{_outputs(args)}: cannot write: {reason}")
        return _fail(f"{shown_path(exc.filename)}: {reason}")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
