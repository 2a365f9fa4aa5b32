"""Bad input's contract, asserted in one place: exit 2, one line on stderr that names the file,
the key and the value, and nothing written."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from cell.cli.main import main


def refused_in_one_line(capsys: Any, argv: list[str], file: Path, key: str, value: str,
                        out: Path) -> None:
    """``cell argv`` refuses ``file`` at ``key = value`` in one line, exit 2, ``out`` unwritten."""
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0
    assert err.startswith(f"cell: error: {file}: {key} = {value}")
    assert not out.exists()
