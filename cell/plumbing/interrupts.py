"""Ending a command that Ctrl-C or kill stopped: at once, with its code.

Kept apart and light (the standard library only), so that ``cell.cli.main`` has it before any
command is imported, and ``cell sweep``, which handles its own stop, shares it.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
from typing import Any


def exit_now(code: int) -> None:
    """End the process now with ``code`` (a command stopped by Ctrl-C or kill, its files
    whole), its streams flushed and another Ctrl-C on the way ignored.  A normal exit could
    still die by SIGINT: CPython does, if the KeyboardInterrupt went through an ``exec`` of a
    string (a dataclass or namedtuple being made while a module was imported)."""
    with contextlib.suppress(ValueError):  # not the main thread: nothing to ignore
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    os._exit(code)


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


class Terminated(KeyboardInterrupt):
    """SIGTERM (``kill``), raised where Ctrl-C would be: every cleanup that Ctrl-C runs
    (temporary folders, half-written files) runs for it too."""


class Stops:
    """SIGINT and SIGTERM while a command runs: the first raises (KeyboardInterrupt, or
    :class:`Terminated`) and is remembered, so that the command ends as stopped even if
    what it raised was swallowed or became another error on its way (ffmpeg, which the
    same Ctrl-C stopped first, breaking its pipe); another is only remembered.  Installed
    only in the main thread; :meth:`restore` puts the previous handlers back."""

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self) -> None:
        self.signum: int | None = None
        self.previous: dict[int, Any] = {}

    def install(self) -> Stops:
        with contextlib.suppress(ValueError, OSError):  # not the main thread: left as it is
            for number in self.SIGNALS:
                self.previous[number] = signal.signal(number, self)
        return self

    def __call__(self, signum: int, frame: object) -> None:
        if self.signum is not None:
            return
        self.signum = signum
        raise Terminated if signum == signal.SIGTERM else KeyboardInterrupt

    def settled(self) -> bool:
        """Whether a stop signal came (one the process has received but whose handler has not
        run yet runs now: a loop's backward jump lets Python run pending handlers)."""
        try:
            for _ in range(2):
                pass
        except KeyboardInterrupt:
            pass
        return self.signum is not None

    def restore(self) -> None:
        with contextlib.suppress(ValueError, OSError, TypeError):
            for number, handler in self.previous.items():
                signal.signal(number, signal.SIG_DFL if handler is None else handler)
        self.previous = {}


def stopped_by(exc: BaseException | None, signum: int | None) -> tuple[int, str]:
    """The exit code and the line of a command stopped by ``signum`` (or, if None, by
    ``exc``, a KeyboardInterrupt or what came of one): 130 ``cell: interrupted`` for
    Ctrl-C, 143 ``cell: terminated`` for kill, as a shell reports them."""
    if signum is None:
        signum = signal.SIGTERM if isinstance(exc, Terminated) else signal.SIGINT
    if signum == signal.SIGTERM:
        return 128 + signum, "cell: terminated"
    return 128 + signum, "cell: interrupted"
