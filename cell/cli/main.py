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
import os
import sys
import warnings
from collections.abc import Sequence
from typing import Any

from cell.cli.parser import SUBPARSERS, UsageError, build_parser, command_module
from cell.cli.said import check_targets, failure_line, shown
from cell.plumbing.errors import one_line
from cell.plumbing.interrupts import Stops, exit_now, interrupted, stopped_by
from cell.plumbing.matplotlib_home import matplotlib_home

#: The exit code of an interrupted command: 128 + SIGINT, as a shell reports Ctrl-C.
INTERRUPTED = 130
#: And of a killed one: 128 + SIGTERM.
TERMINATED = 143

#: The stop signals of the command running in this process (see :class:`Stops`).
_stops = Stops()



def _fail(message: str) -> int:
    if _stops.settled():  # the error came of a stop (ffmpeg, stopped first, failed)
        raise KeyboardInterrupt
    print(f"cell: error: {one_line(message, 1000)}", file=sys.stderr)
    return 2


def _run(args: argparse.Namespace) -> int:
    """The command; a warning that a finished command met is one line each (a refused one's are
    dropped: its error says what went wrong), those Python would show (:func:`shown`).  Not a
    ResourceWarning: an unclosed file reported whenever the collector happens to free it is not
    about the command (Python hides those too), and in-process, as the tests run it, it may be
    another caller's."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        warnings.simplefilter("ignore", ResourceWarning)
        code = int(command_module(args.command).main(args) or 0)
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
    made: list[str] = []  # the folder matplotlib_home makes, named before it is made
    code = 0
    try:
        try:
            stops.arm()
            from cell.plumbing.streams import reader_may_leave, standard_streams

            standard_streams()
            matplotlib_home(made)
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
    except UsageError as exc:  # "cell: error: run: ... (see cell run --help)"
        return _fail(str(exc))
    except SystemExit as exc:  # --help, --version: printed, done
        return exc.code if isinstance(exc.code, int) else 0
    if stdout is not None:
        stdout.product = not getattr(args, "out", None)
    try:
        check_targets(args)
        return _run(args)
    except Exception as exc:  # an anticipated failure is one line (cell.cli.said); a bug, raised
        line = failure_line(exc, args)
        if line is None:
            raise
        return _fail(line)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
