"""Ending a command that Ctrl-C or kill stopped: at once, with its code.

Kept apart and light (the standard library only), so that ``cell.cli.main`` has it before any
command is imported, and ``cell sweep``, which handles its own stop, shares it.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time
from typing import Any

from cell.plumbing.startup import kept_ignored


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
    """SIGINT and SIGTERM while a command runs: the first is remembered and, while the
    command is *armed* (:meth:`arm`: inside the block that turns a stop into its line and
    code), raised (KeyboardInterrupt, or :class:`Terminated`), so that the command ends as
    stopped even if what it raised was swallowed or became another error on its way (ffmpeg,
    which the same Ctrl-C stopped first, breaking its pipe); another is only remembered.

    Outside that block (just installed, not yet armed; disarmed as the block ends) a stop is
    only remembered: raised there, nothing would catch it and Python would print its
    traceback.  :meth:`arm` raises one remembered before it; the caller says one remembered
    after :meth:`disarm`.  A stop raised where Python drops what is raised (a destructor, a
    weakref callback: "Exception ignored in") is raised again (:meth:`lost`).

    Installed only in the main thread, and not for a signal the process was started ignoring
    (cell/plumbing/startup.py); :meth:`restore` puts the previous handlers back."""

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self) -> None:
        self.signum: int | None = None
        self.armed = False
        self.owed = False  # the stop was raised where Python dropped it: to be raised again
        self.lock = threading.Lock()  # owed and armed, between this thread and _again's
        self.previous: dict[int, Any] = {}
        self.hook: Any = None

    def install(self) -> Stops:
        with contextlib.suppress(ValueError, OSError):  # not the main thread: left as it is
            for number in self.SIGNALS:
                if not kept_ignored(number):
                    self.previous[number] = signal.signal(number, self)
            self.hook, sys.unraisablehook = sys.unraisablehook, self.unraisable
        return self

    def __call__(self, signum: int, frame: object) -> None:
        if self.signum is not None and not self.owed:
            return
        self.owed = False
        if self.signum is None:
            self.signum = signum
        if self.armed:
            raise self.exception()

    def exception(self) -> KeyboardInterrupt:
        """What the remembered stop raises: :class:`Terminated` for kill, else KeyboardInterrupt."""
        return Terminated() if self.signum == signal.SIGTERM else KeyboardInterrupt()

    def arm(self) -> None:
        """From now on a stop raises; one that came before raises now."""
        self.armed = True
        if self.signum is not None:
            raise self.exception()

    def disarm(self) -> None:
        """From now on a stop is only remembered."""
        with self.lock:
            self.armed = False

    def unraisable(self, unraisable: Any) -> None:
        """``sys.unraisablehook`` while installed: a stop Python dropped is not printed (a
        traceback before ``cell: interrupted``) but raised again (:meth:`lost`); anything
        else goes to the hook there was."""
        if not self.lost(unraisable.exc_value):
            (self.hook or sys.__unraisablehook__)(unraisable)

    def lost(self, exc: BaseException | None) -> bool:
        """Whether ``exc``, an exception Python dropped (raised in a destructor or a weakref
        callback, where nothing can catch it), was this stop; if so it is owed: another thread
        sends the signal again once the main thread has left this hook, and the handler raises
        it in the main thread, at the next instruction that lets it (or, if that is in another
        destructor, it is dropped and owed again)."""
        if exc is None or not interrupted(exc) or self.signum is None or not self.armed:
            return False
        self.owed = True
        main = threading.main_thread().ident
        threading.Thread(target=self._again, args=(main,), daemon=True,
                         name="cell-stop-again").start()
        return True

    def _again(self, main: int | None) -> None:
        for _ in range(1000):  # (a second or so: else owed to the next signal, said at the end)
            if not self._in_hook(main):
                with self.lock:  # raised only while armed: disarm() and restore() wait for it
                    if self.owed and self.armed and self.signum is not None and main \
                            and hasattr(signal, "pthread_kill"):  # (not on Windows)
                        signal.pthread_kill(main, self.signum)  # wakes it, if it waits
                return
            time.sleep(0.001)

    def _in_hook(self, thread: int | None) -> bool:
        """Whether ``thread`` is in :meth:`unraisable` (what the handler raised there would be
        dropped once more, and reported as the hook's own failure)."""
        frame = sys._current_frames().get(thread or 0)
        while frame is not None:
            if frame.f_code is Stops.unraisable.__code__:
                return True
            frame = frame.f_back
        return False

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
        with self.lock:
            self.owed = False
        self.settled()  # a signal sent again just now: handled here, not by the next handler
        with contextlib.suppress(ValueError, OSError, TypeError):
            for number, handler in self.previous.items():
                signal.signal(number, signal.SIG_DFL if handler is None else handler)
        if self.previous and sys.unraisablehook == self.unraisable:
            sys.unraisablehook = self.hook
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
