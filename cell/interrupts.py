"""Ending a command that Ctrl-C or kill stopped: at once, with its code.

Kept apart and light (the standard library only), so that ``cell.cli`` has it before any
command is imported, and ``cell sweep``, which handles its own stop, shares it.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys


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
