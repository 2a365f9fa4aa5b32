"""The package's one caching mechanism: results memoised on what they depend on.

A cached function names its key explicitly: plain, hashable values (frozen
dataclasses of the maths, numbers, tuples), or :func:`file_key` for something
read from a file (its resolved path, size and modification time, so an edited
file is read again).  Nothing is keyed on a whole scenario, so no cached value
can silently carry another scenario's settings.
"""

from __future__ import annotations

import functools
import os
from collections import OrderedDict
from collections.abc import Callable, Hashable
from pathlib import Path
from typing import Any, Generic, ParamSpec, TypeVar

P = ParamSpec("P")
R = TypeVar("R")


class Memo(Generic[P, R]):
    """``fn`` memoised on ``key(*args, **kwargs)``; the ``maxsize`` most recent are kept."""

    def __init__(self, fn: Callable[P, R], key: Callable[P, Hashable], maxsize: int):
        self.fn, self.key, self.maxsize = fn, key, maxsize
        self._store: OrderedDict[Hashable, R] = OrderedDict()
        functools.update_wrapper(self, fn)

    def __call__(self, *args: P.args, **kwargs: P.kwargs) -> R:
        k = self.key(*args, **kwargs)
        store = self._store
        if k in store:
            store.move_to_end(k)
            return store[k]
        value = self.fn(*args, **kwargs)
        store[k] = value
        if len(store) > self.maxsize:
            store.popitem(last=False)
        return value

    def clear(self) -> None:
        self._store.clear()

    def __len__(self) -> int:
        return len(self._store)


def memo(key: Callable[..., Hashable] | None = None, maxsize: int = 32
         ) -> Callable[[Callable[P, R]], Memo[P, R]]:
    """Decorator: memoise on ``key(*args, **kwargs)`` (default: the arguments themselves)."""
    def by_args(*args: Any, **kwargs: Any) -> Hashable:
        return args + tuple(sorted(kwargs.items()))

    def wrap(fn: Callable[P, R]) -> Memo[P, R]:
        return Memo(fn, key or by_args, maxsize)

    return wrap


def file_key(path: str | Path) -> tuple[str, int, int]:
    """A file's identity for a cache: resolved path, size and modification time (ns)."""
    p = Path(path).resolve()
    st = os.stat(p)
    return str(p), st.st_size, st.st_mtime_ns
