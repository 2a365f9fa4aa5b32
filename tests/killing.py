"""Fault injection for the kill tests: the k-th file-system step of ``cell.plumbing.output.atomic`` kills the
process with SIGKILL, as a power cut or ``kill -9`` would, at every step in turn."""

from __future__ import annotations

import os
import signal
from collections.abc import Callable
from typing import Any

import cell.plumbing.output.atomic as output

#: The ``os`` functions counted as steps (with ``cell.plumbing.output.atomic``'s open and exchange).
STEPS = ("rename", "replace", "unlink", "rmdir", "mkdir", "fsync", "link")


def die_at_step(k: int, fallback: bool = False) -> None:
    """Count every open, exchange and ``STEPS`` call from now on; SIGKILL this process at the
    ``k``-th.  ``fallback``: behave as on a system without an atomic exchange (renameat2)."""
    calls = [0]

    def trap(function: Callable[..., Any]) -> Callable[..., Any]:
        def trapped(*args: Any, **kwargs: Any) -> Any:
            calls[0] += 1
            if calls[0] == k:
                os.kill(os.getpid(), signal.SIGKILL)
            return function(*args, **kwargs)
        return trapped

    if fallback:
        output._exchange = lambda a, b: False  # noqa: SLF001 - the point: no exchange
    output._exchange, output._open = trap(output._exchange), trap(output._open)  # noqa: SLF001
    for name in STEPS:
        setattr(os, name, trap(getattr(os, name)))
