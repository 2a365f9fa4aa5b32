"""Progress that reads well both on a terminal and in a log.

On a terminal, a tqdm bar.  Anywhere else (stderr sent to a file, CI), a bar's
carriage returns would pile up into one long line, so :class:`Progress` prints
an occasional whole line instead, each time another tenth of the work is done
or half a minute has passed, and one when the work ends::

    sweep: 1,400/2,800 replications (50 %), 4.2 s elapsed, ~4 s left
    sweep: 2,800/2,800 replications (100 %), done in 8.3 s
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Iterable, Iterator
from types import TracebackType
from typing import IO, Any, TypeVar

T = TypeVar("T")

#: A plain line at least every this fraction of the work ...
EVERY_FRACTION = 0.1
#: ... and at least every this many seconds.
EVERY_S = 30.0


def is_terminal(stream: IO[str]) -> bool:
    """Whether ``stream`` is an interactive terminal (a closed or odd stream is not)."""
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


class Progress:
    """Count ``total`` units of work: a tqdm bar on a terminal, occasional lines elsewhere.

    ``enabled=False`` shows nothing.  ``clock`` (seconds, monotonic) is for tests.
    """

    def __init__(self, total: int, desc: str, unit: str, *, file: IO[str] | None = None,
                 enabled: bool = True, every_fraction: float = EVERY_FRACTION,
                 every_s: float = EVERY_S, clock: Callable[[], float] = time.monotonic):
        self.total, self.desc, self.unit = int(total), desc, unit
        self.file: IO[str] = file if file is not None else sys.stderr
        self.n = 0
        self.every_fraction, self.every_s, self.clock = every_fraction, every_s, clock
        self.started = clock()
        self._last_line_s = self.started
        self._last_line_n = 0
        self._closed = False
        self.bar: Any = None
        """The tqdm bar, on a terminal."""
        self.enabled = enabled and self.total > 0
        if self.enabled and is_terminal(self.file):
            from tqdm import tqdm

            self.bar = tqdm(total=self.total, desc=desc, unit=unit, file=self.file, leave=False,
                            dynamic_ncols=True)

    @property
    def lines(self) -> bool:
        """Whether progress goes out as plain lines (enabled, and not a terminal)."""
        return self.enabled and self.bar is None

    def grow(self, n: int) -> None:
        """``n`` more units of work than first said (a sweep's next round)."""
        self.total += n
        if self.bar is not None:
            self.bar.total = self.total
            self.bar.refresh()

    def update(self, n: int = 1) -> None:
        """``n`` more units done."""
        self.n += n
        if self.bar is not None:
            self.bar.update(n)
        elif self.lines and self.n < self.total:
            now = self.clock()
            step = max(1, int(self.total * self.every_fraction))
            if (self.n // step > self._last_line_n // step
                    or now - self._last_line_s >= self.every_s):
                self._line(now)

    def _line(self, now: float) -> None:
        elapsed = now - self.started
        done = self.n / self.total
        text = (f"{self.desc}: {self.n:,}/{self.total:,} {self.unit} ({100 * done:.0f} %), "
                f"{elapsed:.1f} s elapsed")
        if 0 < self.n < self.total:
            text += f", ~{elapsed * (1 - done) / done:.0f} s left"
        self.file.write(text + "\n")
        self.file.flush()
        self._last_line_s, self._last_line_n = now, self.n

    def close(self) -> None:
        """End the bar, or write the closing line if all the work was done."""
        if self._closed:
            return
        self._closed = True
        if self.bar is not None:
            self.bar.close()
        elif self.lines and self.n >= self.total:
            elapsed = self.clock() - self.started
            self.file.write(f"{self.desc}: {self.n:,}/{self.total:,} {self.unit} (100 %), "
                            f"done in {elapsed:.1f} s\n")
            self.file.flush()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


def progress(items: Iterable[T], desc: str, unit: str, *, total: int | None = None,
             file: IO[str] | None = None, enabled: bool = True,
             clock: Callable[[], float] = time.monotonic) -> Iterator[T]:
    """Yield ``items``, counting each as one unit of :class:`Progress`."""
    if total is None:
        total = len(items)  # type: ignore[arg-type]
    with Progress(total, desc, unit, file=file, enabled=enabled, clock=clock) as bar:
        for item in items:
            yield item
            bar.update()
