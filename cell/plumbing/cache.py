"""The package's one caching mechanism: results memoised on what they depend on.

A cached function names its key explicitly: plain, hashable values (frozen
dataclasses of the maths, numbers, tuples), or :func:`file_key` for something
read from a file (its resolved path, size and modification time, so an edited
file is read again).  Nothing is keyed on a whole scenario's value, so no cached
value can silently carry another scenario's settings; a sweep's assembled cell is
kept only for the same scenario object (:class:`Identity`).

What is slow to solve and needed at every start (the robot's timing, the
arrivals' distribution facts) is also kept on disk (:func:`stored`,
:func:`store`): one JSON file per value under ``$XDG_CACHE_HOME/cell/`` (or
``~/.cache/cell/``), keyed on the plain values it depends on and on
:func:`code_fingerprint` (this package's source, numpy's and scipy's versions),
written atomically and checked by a checksum.  An entry that is missing,
unreadable or damaged, or a cache directory that cannot be written, only means
the value is computed again; ``CELL_NO_CACHE=1`` turns the disk cache off.  A
stored value is exactly the computed one (floats round-trip through JSON), so
the cache never changes a result.

What it buys (a fresh process's ``cell run baseline``, the disk cache warm against
``CELL_NO_CACHE=1``, on a shared 2-core machine): 4.1-5.5 s against 6.0-8.8 s, the robot's
timing solved again each start; so it stays.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import tempfile
import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable
from pathlib import Path
from typing import Any, Generic, ParamSpec, TypeVar

P = ParamSpec("P")
R = TypeVar("R")


#: Every memo and every remembered kind of value in this process (for :func:`forget`).
_IN_PROCESS: list[Memo[Any, Any] | Remembered[Any]] = []


def forget() -> None:
    """Forget every value remembered in this process; the disk cache stays as it is."""
    for kept in _IN_PROCESS:
        kept.clear()


class Memo(Generic[P, R]):
    """``fn`` memoised on ``key(*args, **kwargs)``; the ``maxsize`` most recent are kept."""

    def __init__(self, fn: Callable[P, R], key: Callable[P, Hashable], maxsize: int):
        self.fn, self.key, self.maxsize = fn, key, maxsize
        self._store: OrderedDict[Hashable, R] = OrderedDict()
        self._lock = threading.Lock()
        functools.update_wrapper(self, fn)
        _IN_PROCESS.append(self)

    def __call__(self, *args: P.args, **kwargs: P.kwargs) -> R:
        k = self.key(*args, **kwargs)
        store = self._store
        with self._lock:  # a threaded dask worker runs replications side by side
            if k in store:
                store.move_to_end(k)
                return store[k]
        value = self.fn(*args, **kwargs)  # not under the lock: others' values go on
        with self._lock:
            store[k] = value
            if len(store) > self.maxsize:
                store.popitem(last=False)
        return value

    def clear(self) -> None:
        with self._lock:
            self._store.clear()

    def __len__(self) -> int:
        return len(self._store)


class Identity:
    """A key that is one object, by identity (``memo(key=Identity)``): for a value made from
    an object that is the same for a while (a sweep task's scenario).  The key holds its
    object, so the object's id cannot be reused while the value is kept."""

    __slots__ = ("obj",)

    def __init__(self, obj: object):
        self.obj = obj

    def __hash__(self) -> int:
        return id(self.obj)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Identity) and other.obj is self.obj


def memo(key: Callable[..., Hashable] | None = None, maxsize: int = 32
         ) -> Callable[[Callable[P, R]], Memo[P, R]]:
    """Decorator: memoise on ``key(*args, **kwargs)`` (default: the arguments themselves)."""
    def by_args(*args: Any, **kwargs: Any) -> Hashable:
        return args + tuple(sorted(kwargs.items()))

    def wrap(fn: Callable[P, R]) -> Memo[P, R]:
        return Memo(fn, key or by_args, maxsize)

    return wrap


class Remembered(Generic[R]):
    """Values of one ``kind`` solved once for good: kept in this process, and on disk for the
    next one (:func:`stored`, :func:`store`).  ``key`` is plain JSON data, the values the
    result depends on; ``to_plain`` and ``from_plain`` turn a value into JSON data and back
    (a stored value that cannot be read back is a miss)."""

    def __init__(self, kind: str, to_plain: Callable[[R], Any] = lambda v: v,
                 from_plain: Callable[[Any], R] = lambda v: v):
        self.kind, self.to_plain, self.from_plain = kind, to_plain, from_plain
        self._here: dict[str, R] = {}
        _IN_PROCESS.append(self)

    def get(self, key: Any) -> R | None:
        """The value remembered for ``key``, here or on disk; None if there is none."""
        text = _text(key)
        if text is None:
            return None
        found = self._here.get(text)
        if found is not None:
            return found
        plain = _stored(self.kind, text)
        if plain is None:
            return None
        try:
            found = self.from_plain(plain)
        except (TypeError, KeyError, AttributeError, ValueError):
            return None
        self._here[text] = found
        return found

    def put(self, key: Any, value: R) -> None:
        """Remember ``value`` for ``key``, here and on disk (a value the disk cannot take
        is kept here only)."""
        text = _text(key)
        if text is None or text in self._here:
            return
        self._here[text] = value
        try:
            plain = self.to_plain(value)
        except TypeError:
            return
        _store(self.kind, text, plain)

    def clear(self) -> None:
        self._here.clear()


def _text(key: Any) -> str | None:
    """A key as text (None for one that is not plain JSON data: then nothing is kept); the
    disk cache's entries are keyed on this text too."""
    try:
        return json.dumps(key, sort_keys=True, allow_nan=True)
    except (TypeError, ValueError):
        return None


def file_key(path: str | Path) -> tuple[str, int, int]:
    """A file's identity for a cache: resolved path, size and modification time (ns)."""
    p = Path(path).resolve()
    st = os.stat(p)
    return str(p), st.st_size, st.st_mtime_ns


# --------------------------------------------------------------------------- on disk
#: Set to anything but "" or "0" to turn the disk cache off.
NO_CACHE_ENV = "CELL_NO_CACHE"
_MAGIC = b"cell-cache 1\n"


def cache_dir() -> Path | None:
    """``$XDG_CACHE_HOME/cell`` (default ``~/.cache/cell``); None if ``CELL_NO_CACHE`` is set
    or there is no absolute place for it.  A relative ``XDG_CACHE_HOME`` is ignored (as the
    XDG specification asks), and a relative home gives no disk cache: neither may leave a
    cache folder in the working directory."""
    if os.environ.get(NO_CACHE_ENV, "") not in ("", "0"):
        return None
    base = os.environ.get("XDG_CACHE_HOME", "")
    if not os.path.isabs(base):
        home = os.path.expanduser("~")
        if not os.path.isabs(home):
            return None
        base = os.path.join(home, ".cache")
    return Path(base) / "cell"


@functools.lru_cache(maxsize=1)
def code_fingerprint() -> str:
    """What a stored value was computed with: this package's source (its version
    included), numpy's version and scipy's, and Python's."""
    import sys
    from importlib.util import find_spec

    import numpy as np

    h = hashlib.sha256()
    package = Path(__file__).resolve().parent.parent
    for path in sorted(package.rglob("*.py")):
        h.update(str(path.relative_to(package)).encode() + b"\0" + path.read_bytes() + b"\0")
    spec = find_spec("scipy")
    if spec is not None and spec.origin is not None:
        version = Path(spec.origin).with_name("version.py")
        h.update(version.read_bytes() if version.is_file() else spec.origin.encode())
    h.update(f"{np.__version__} {sys.version}".encode())
    return h.hexdigest()


def _key_text(kind: str, key_text: str) -> tuple[str, str]:
    """The kind and key (:func:`_text`) as text, and the whole of what an entry must match
    (the code's fingerprint too)."""
    text = f"{kind}\n{key_text}"
    return text, f"{code_fingerprint()}\n{text}"


def _entry(text: str, kind: str) -> Path | None:
    """The entry's file: one per key, whatever the code's version (a new version's value
    replaces the old one's), so the directory does not grow as the code changes."""
    where = cache_dir()
    if where is None:
        return None
    return where / f"{kind}-{hashlib.sha256(text.encode()).hexdigest()[:40]}.json"


def stored(kind: str, key: Any) -> Any:
    """The value stored under (``kind``, ``key``), or None: none stored, the cache off,
    or an entry that cannot be read or fails its checksum (then it is recomputed).

    ``key`` is plain JSON data (numbers, strings, lists, mappings): the values the
    stored result depends on.  Floats are written and read back exactly.
    """
    text = _text(key)
    return None if text is None else _stored(kind, text)


def _stored(kind: str, key_text: str) -> Any:
    """:func:`stored`, the key already text (:func:`_text`)."""
    try:
        text, whole = _key_text(kind, key_text)
        path = _entry(text, kind)
        if path is None:
            return None
        data = path.read_bytes()
        if not data.startswith(_MAGIC):
            return None
        digest, payload = data[len(_MAGIC):len(_MAGIC) + 64], data[len(_MAGIC) + 65:]
        if hashlib.sha256(payload).hexdigest().encode() != digest:
            return None
        entry = json.loads(payload)
        if not isinstance(entry, dict) or entry.get("key") != whole:
            return None
        return entry.get("value")
    except Exception:  # noqa: BLE001 - an unusable cache is only a cache miss
        return None


def store(kind: str, key: Any, value: Any) -> None:
    """Store ``value`` (plain JSON data) under (``kind``, ``key``), atomically; a cache
    that cannot be written is left alone, silently."""
    text = _text(key)
    if text is not None:
        _store(kind, text, value)


def _store(kind: str, key_text: str, value: Any) -> None:
    """:func:`store`, the key already text (:func:`_text`).  Folders it made for an entry
    it could not write (a restrictive umask, a read-only place) are removed again."""
    tmp = None
    made: list[Path] = []
    try:
        text, whole = _key_text(kind, key_text)
        path = _entry(text, kind)
        if path is None:
            return
        payload = json.dumps({"key": whole, "value": value}).encode()
        digest = hashlib.sha256(payload).hexdigest().encode()
        for folder in [*reversed(path.parent.parents), path.parent]:
            if not os.path.isdir(folder):
                with contextlib.suppress(FileExistsError):  # (another process's, just made)
                    os.mkdir(folder)
                    made.append(folder)
        fd, tmp = tempfile.mkstemp(prefix=".tmp-", dir=path.parent)
        with os.fdopen(fd, "wb") as fh:
            fh.write(_MAGIC + digest + b"\n" + payload)
        os.replace(tmp, path)
        tmp = None
    except Exception:  # noqa: BLE001 - an unwritable cache is only a cache miss next time
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            tmp = None
        for folder in reversed(made):
            with contextlib.suppress(OSError):
                os.rmdir(folder)
    finally:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
