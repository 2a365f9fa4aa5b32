"""A map's report folder, shared by the stress, sensor and reliability maps: its table as CSV,
its figure as PNG and its README, written as one set, and the ``python -m`` entry that makes it
(one line and exit 2 on bad input)."""

from __future__ import annotations

import io
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pandas as pd

from cell.plumbing.output.atomic import OutputDir


def files(name: str) -> tuple[str, str, str]:
    """The folder's files: NAME.csv, NAME.png and README.md."""
    return f"{name}.csv", f"{name}.png", "README.md"


def check(out_dir: str | Path, name: str) -> None:
    """Refuse before any work a folder that cannot take the set."""
    OutputDir.check(out_dir, files(name), option="DIR")


def png_bytes(fig: Any) -> bytes:
    """A figure as PNG bytes with no software stamp, so the same figure is the same file."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    return buf.getvalue()


def write_set(out_dir: str | Path, name: str, table: pd.DataFrame, png: bytes, text: str) -> Path:
    """The table, figure and reading, appearing together or not at all."""
    csv, figure, readme = files(name)
    with OutputDir(out_dir, files(name), option="DIR") as out:
        out.write_csv(csv, table)
        with out.open(figure, "wb") as fh:
            fh.write(png)
        out.write_text(readme, text)
    return Path(out_dir)


def command_line(module: str, make: Callable[..., Path], count: int, optional: int = 0) -> None:
    """``python -m MODULE ARG...``: make the report from ``count`` arguments and up to
    ``optional`` more."""
    from cell.plumbing.errors import CellError

    given = len(sys.argv) - 1
    if not count <= given <= count + optional:  # e.g. the replications file and the report's folder
        more = "".join(f" [ARG{i + 1}]" for i in range(count, count + optional))
        print(f"usage: python -m {module} {' '.join(f'ARG{i + 1}' for i in range(count))}{more} "
              f"(given {given})", file=sys.stderr)
        sys.exit(2)
    try:
        print(f"wrote {make(*sys.argv[1:1 + given])}")
    except (CellError, OSError) as exc:  # bad input, or a replications file not there
        print(f"{module}: error: {exc}", file=sys.stderr)
        sys.exit(2)
