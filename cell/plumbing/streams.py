"""What a command prints, kept from ending the command when its reader goes away.

A command's product is its files (or, for a listing, what it has printed); what it prints
beside them is commentary.  If the reader of stdout or stderr leaves (``cell run ... | head -1``,
``2>&1 | head``), :func:`reader_may_leave` (around every command, in ``cell.cli.main``) points that
stream at the null device and the command carries on: its files are written whole and it ends
with its own exit code, where the closed pipe used to stop it half-way (nothing written,
exit 0) or fail the interpreter's last flush (exit 120).

A reader that left (``EPIPE``) is no error; standard output that cannot be written for another
reason (a full device, ``ENOSPC``; an I/O error, ``EIO``) is, when what it prints is the
command's product (:attr:`Guarded.product`: ``cell fit`` or ``cell compare`` without ``--out``),
which it would have lost saying nothing.  The stream is silenced the same way, so the command
still ends whole, and :attr:`Guarded.failed` keeps the error for ``cell.cli.main`` to end the
command with one line and exit 2; beside files, what is printed is commentary and its loss no
error.
"""

from __future__ import annotations

import contextlib
import errno
import os
import sys
from collections.abc import Iterator
from typing import Any, TextIO

#: Errors that mean the reader of a stream went away (``| head``): no error of the command's.
READER_GONE = frozenset({errno.EPIPE, errno.ECONNRESET, errno.ESHUTDOWN})


class Guarded:
    """A text stream whose writes and flushes survive a reader that has gone (see the module);
    :attr:`failed`, the error that silenced it if that was not the reader leaving."""

    def __init__(self, stream: TextIO):
        self.stream = stream
        self.gone = False
        self.failed: OSError | None = None
        self.product = False  # what is written here is the command's product, not commentary

    def __getattr__(self, name: str) -> Any:  # isatty, fileno, encoding...: the stream's own
        return getattr(self.stream, name)

    def write(self, text: str) -> int:
        if not self.gone:
            try:
                return self.stream.write(text)
            except (OSError, ValueError) as exc:  # the reader left, the device is full, closed
                self._silence(exc)
        return len(text)

    def flush(self) -> None:
        if not self.gone:
            try:
                self.stream.flush()
            except (OSError, ValueError) as exc:
                self._silence(exc)

    def _silence(self, exc: BaseException) -> None:
        """Send the stream, and what its buffer still holds, to the null device from now on;
        ``exc``, what it met, kept in :attr:`failed` unless the reader left."""
        self.gone = True
        if isinstance(exc, OSError) and exc.errno not in READER_GONE:
            self.failed = exc
        with contextlib.suppress(OSError, ValueError, AttributeError):  # no descriptor: just drop
            devnull = os.open(os.devnull, os.O_WRONLY)
            try:
                os.dup2(devnull, self.stream.fileno())
            finally:
                os.close(devnull)


def _null_stream(fd: int) -> TextIO:
    """A text stream on descriptor ``fd`` (the null device put there), or on the null device."""
    try:
        return open(fd, "w", closefd=False, errors="backslashreplace")  # noqa: SIM115
    except OSError:
        return open(os.devnull, "w")  # noqa: SIM115


def standard_streams() -> None:
    """Standard input, output and error open whatever the caller closed (``cell run >&-``):
    a closed descriptor 0, 1 or 2 gets the null device, so no file the command opens takes
    its number (and receives what is printed), and ``sys.stdout``/``sys.stderr``, which
    Python leaves None then, a stream on it.  Called first thing, before any file is open."""
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            with contextlib.suppress(OSError):
                got = os.open(os.devnull, os.O_RDWR)
                if got != fd:
                    os.dup2(got, fd)
                    os.close(got)
    if sys.stdout is None:
        sys.stdout = _null_stream(1)
    if sys.stderr is None:
        sys.stderr = _null_stream(2)


@contextlib.contextmanager
def reader_may_leave() -> Iterator[Guarded]:
    """``sys.stdout`` and ``sys.stderr`` guarded for the block, and flushed at its end; gives
    the guarded standard output (its :attr:`~Guarded.failed` read after the block)."""
    saved = sys.stdout, sys.stderr
    out, err = Guarded(saved[0]), Guarded(saved[1])
    sys.stdout, sys.stderr = out, err
    try:
        yield out
        out.flush()
        err.flush()
    finally:
        if sys.stdout is out:
            sys.stdout = saved[0]
        if sys.stderr is err:
            sys.stderr = saved[1]
