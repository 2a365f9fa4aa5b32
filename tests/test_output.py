"""Atomic output: whole or nothing, and readable like any new file."""

import os
import stat

import pandas as pd
import pytest

from cell.output import atomic_path, write_csv


def test_written_whole_with_ordinary_permissions(tmp_path):
    target = tmp_path / "sub" / "a.csv"
    write_csv(pd.DataFrame({"x": [1.5, 2.0]}), target)
    assert target.read_text() == "x\n1.5\n2\n"
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~umask
    assert [p.name for p in target.parent.iterdir()] == ["a.csv"]


def test_failure_leaves_nothing_and_keeps_the_old_file(tmp_path):
    target = tmp_path / "a.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("disk full")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"]
