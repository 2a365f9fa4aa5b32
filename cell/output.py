"""Output files are written whole or not at all: to a temporary file beside the
target, then renamed over it (atomic on POSIX)."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pandas as pd


def _file_mode() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


#: The mode an ordinary new file gets (0644 under the usual umask).
_FILE_MODE = _file_mode()

#: Digits kept in CSV floats: enough to round-trip, identical on every run.
FLOAT_FORMAT = "%.10g"


@contextlib.contextmanager
def atomic_path(target: str | Path) -> Iterator[Path]:
    """Yield a temporary path; on success it replaces ``target``, on error it is removed."""
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        tmp_path.chmod(_FILE_MODE)  # mkstemp makes 0600; outputs are for everyone to read
        os.replace(tmp_path, target)
    finally:
        tmp_path.unlink(missing_ok=True)


def write_text(text: str, target: str | Path) -> None:
    with atomic_path(target) as tmp:
        tmp.write_text(text)


def write_csv(frame: pd.DataFrame, target: str | Path, float_format: str = FLOAT_FORMAT) -> None:
    """A DataFrame as CSV, atomically, with a fixed float format (byte-identical reruns)."""
    with atomic_path(target) as tmp:
        frame.to_csv(tmp, index=False, float_format=float_format, lineterminator="\n")
