"""Floats in every CSV cell writes: ten significant digits, a whole number with its ``.0``,
so that pandas reads a float column as floats whatever its values (parts.csv's
``feed_delay_s`` is all 0 in a run that never holds a part)."""

from __future__ import annotations

import math
import typing

import pandas as pd
from hypothesis import given
from hypothesis import strategies as st

from cell.cli.main import main
from cell.plumbing.output.atomic import float_text
from cell.sim.records import PartRecord


@given(st.floats(allow_nan=False, min_value=-1e300, max_value=1e300) | st.integers(-10**9, 10**9).map(float))
def test_a_float_reads_back_as_a_float_within_ten_digits(x):
    """(Ten digits of the largest doubles round past the largest: no figure is near.)"""
    text = float_text(x)
    back = pd.read_csv(pd.io.common.StringIO(f"x\n{text}\n"))["x"]
    assert back.dtype == float
    assert back[0] == x or math.isclose(back[0], x, rel_tol=1e-9)


def test_whole_floats_keep_their_point_and_others_are_as_printf_writes_them():
    assert [float_text(v) for v in (21.0, 0.0, -0.0, -3.0, 1e20, 22.5872, float("inf"))] == \
        ["21.0", "0.0", "-0.0", "-3.0", "1e+20", "22.5872", "inf"]


def test_a_runs_float_columns_are_floats_in_pandas_even_when_whole(tmp_path):
    assert main(["run", "baseline", "--set", "run.parts=30", "--out", str(tmp_path)]) == 0
    parts = pd.read_csv(tmp_path / "parts.csv")
    floats = [name for name, kind in typing.get_type_hints(PartRecord).items() if kind is float]
    assert "feed_delay_s" in floats and (parts["feed_delay_s"].fillna(0) == 0).all()
    assert {name: str(parts[name].dtype) for name in floats} == {name: "float64" for name in floats}
    summary = pd.read_csv(tmp_path / "summary.csv")
    assert summary["feed_delay_max_s"].dtype == float and summary["parts_delivered"].dtype == int
