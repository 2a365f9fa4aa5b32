"""Ctrl-C and kill from the command's first instant: the first code of ``cell`` to run.

``cell/__init__.py`` imports this module before anything else, so ``python -m cell`` and the
``cell`` console script (both import the package first) have it before any other module of
theirs is read.  If this process is the command (:func:`is_the_command`; not a program or a
test that imports the package), SIGINT and SIGTERM end it at once with ``cell: interrupted``
(exit 130) or ``cell: terminated`` (143), as :mod:`cell.cli.main` says them once it runs:
nothing of the command exists yet, so nothing is left behind.  ``cell.cli.main.main``
replaces these handlers with its own (:class:`cell.plumbing.interrupts.Stops`) and puts them
back when the command ends, so a signal while the process exits is said the same way, its
outputs whole.

Before this module runs, the interpreter's own start-up (its initialisation, ``site`` and
the ``.pth`` files of the environment, ``runpy`` or the console script's first line: about
15-40 ms) has Python's defaults: SIGINT raises KeyboardInterrupt, whose traceback Python
prints before it ends by SIGINT (unless it is raised in a weakref callback of importlib's, which
Python reports as "Exception ignored in" and drops, CPython issue 95959: the command then runs
to its end); SIGTERM ends the process at once.  No code of a package can
run earlier, and nothing of ``cell`` exists then either.

The standard library only (``os`` and ``sys`` are loaded already; ``signal`` adds ``enum``
where ``site`` did not import it: a millisecond or two).
"""

from __future__ import annotations

import os
import signal
import sys

#: The exit code and the line of each stop signal (as :func:`cell.plumbing.interrupts.stopped_by`).
LINES: dict[int, tuple[int, bytes]] = {
    signal.SIGINT: (128 + signal.SIGINT, b"cell: interrupted\n"),
    signal.SIGTERM: (128 + signal.SIGTERM, b"cell: terminated\n"),
}
#: What the console script is called, as the kernel ran it.
SCRIPTS = ("cell", "cell.exe", "cell-script.py")
#: The modules ``python -m`` runs as the command.
MODULES = ("cell", "cell.__main__", "cell.cli.main")


def is_the_command(argv: list[str], orig_argv: list[str]) -> bool:
    """Whether this process is ``python -m cell`` (``argv[0]`` is ``-m`` while the package is
    found) or the ``cell`` script, as the interpreter was started (``orig_argv``): not a
    multiprocessing child, whose ``sys.argv`` is its parent's."""
    if not argv or len(orig_argv) < len(argv) + 1:
        return False
    start = len(orig_argv) - len(argv)
    if orig_argv[start + 1:] != argv[1:]:
        return False
    if argv[0] == "-m":
        return orig_argv[start] in MODULES and orig_argv[start - 1] == "-m"
    return orig_argv[start] == argv[0] and os.path.basename(argv[0]) in SCRIPTS


def stop_now(signum: int, frame: object) -> None:
    """End the process with the signal's code and line (streams flushed; another signal on
    the way ignored)."""
    for number in LINES:
        signal.signal(number, signal.SIG_IGN)
    code, line = LINES.get(signum, LINES[signal.SIGINT])
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except Exception:  # noqa: BLE001, S110 - closed, full, or cut short by this signal
            pass
    try:
        os.write(2, line)
    except OSError:  # standard error closed
        pass
    os._exit(code)


def kept_ignored(number: int) -> bool:
    """Whether signal ``number`` is ignored, as the process may have been started (SIGINT in a
    shell script's background job, so that the script's Ctrl-C spares it): cell then leaves
    it ignored, as Python itself does."""
    return signal.getsignal(number) is signal.SIG_IGN


def install() -> bool:
    """:func:`stop_now` for SIGINT and SIGTERM, if this process is the command; whether it
    was installed; not for a signal the process was started ignoring (:func:`kept_ignored`)."""
    if not is_the_command(sys.argv, getattr(sys, "orig_argv", [])):
        return False
    try:
        for number in LINES:
            if not kept_ignored(number):
                signal.signal(number, stop_now)
    except (ValueError, OSError):  # not the main thread, or not allowed
        return False
    return True


INSTALLED = install()
