"""Bounded work for ``cell fit``: a time budget per family, and a subsample for the MLE of a
long trace.

Some scipy families have no closed-form density or moments (``studentized_range``
integrates numerically: its start values alone take seconds, its fit minutes), so a
family's fit runs under :func:`time_limit`, and one that overruns is left out with a line
saying so.  A long trace is fitted on :func:`subsample` of it, drawn with a fixed seed so the
same trace gives the same fit.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
from numpy.typing import NDArray

#: Seconds each family's fit may take by default (``cell fit --budget``).
DEFAULT_BUDGET_S = 20.0
#: At most this many values go into the maximum-likelihood fits; a longer trace is
#: subsampled (:func:`subsample`).  A three-parameter Weibull fit costs about 0.3 s per
#: thousand values, and with 5,000 values its parameters' sampling error is already below
#: what a what-if can tell apart.
MAX_FIT_VALUES = 5_000
#: The seed of :func:`subsample`'s draw: the same trace gives the same subsample.
SUBSAMPLE_SEED = 20_260_301


class OutOfTime(BaseException):
    """A fit ran past its budget.  A BaseException, so that no ``except Exception`` inside
    scipy swallows it on the way out."""


def can_bound() -> bool:
    """Whether :func:`time_limit` can stop a fit here: an interval timer (POSIX) in the
    main thread, where Python delivers its signal."""
    return hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()


@contextmanager
def time_limit(seconds: float | None) -> Iterator[None]:
    """Raise :class:`OutOfTime` in the block once ``seconds`` have passed (``None``: no limit;
    nor where :func:`can_bound` is false).  The real-time interval timer and SIGALRM's
    handler are put back as they were, the timer with what remained of it."""
    if seconds is None or not can_bound():
        yield
        return

    def _alarm(signum: int, frame: object) -> None:
        raise OutOfTime

    old_handler = signal.signal(signal.SIGALRM, _alarm)
    old_delay, old_interval = signal.setitimer(signal.ITIMER_REAL, seconds)
    start = time.monotonic()
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old_handler)
        if old_delay > 0.0:  # someone else's timer: it keeps running
            left = max(old_delay - (time.monotonic() - start), 1e-3)
            signal.setitimer(signal.ITIMER_REAL, left, old_interval)


def subsample(x: NDArray[Any], most: int = MAX_FIT_VALUES) -> NDArray[Any]:
    """``x`` itself if it has at most ``most`` values; else ``most`` of them drawn without
    replacement with :data:`SUBSAMPLE_SEED`, in their order in ``x``."""
    if x.size <= most:
        return x
    rng = np.random.default_rng(SUBSAMPLE_SEED)
    return x[np.sort(rng.choice(x.size, size=most, replace=False))]
