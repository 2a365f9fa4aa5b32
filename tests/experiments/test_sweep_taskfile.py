"""The task files and replications.csv written through the csv module
(:mod:`cell.experiments.sweep.taskfile`, :mod:`cell.experiments.sweep.results`) hold the bytes pandas writes:
``DataFrame.from_records(...).to_csv`` for a task, ``read_csv`` of each task then
``reindex(...).to_csv`` for the assembled file, on rows of every kind a summary holds."""

from __future__ import annotations

import io
import math

import pandas as pd
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.experiments.sweep.results import TASK_FLOAT_FORMAT, write_rows, write_task
from cell.experiments.sweep.taskfile import read_task_text, task_csv
from cell.plumbing.output.atomic import float_formatter

FLOATS = st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=64),
                   st.integers(-10**6, 10**6).map(float), st.sampled_from([0.1, 1e-300, 2.5e17]))
TEXT = st.one_of(st.sampled_from(["thesis", "a,b", 'say "hi"', "NA", "", "1", "True", " x",
                                  "adaptive", "line\nbreak", "nan"]),
                 st.text(alphabet="abc,\"' 019.eE-", max_size=6))
#: A column's values: one kind, or the mixes a summary can hold (None for undefined).
COLUMN = st.one_of(
    st.lists(st.integers(-2**40, 2**40), min_size=1, max_size=1),
    st.lists(FLOATS, min_size=1, max_size=1), st.lists(st.booleans(), min_size=1, max_size=1),
    st.lists(TEXT, min_size=1, max_size=1), st.lists(st.none(), min_size=1, max_size=1),
    st.lists(st.one_of(FLOATS, st.none(), st.integers(-99, 99)), min_size=1, max_size=1),
    st.lists(st.one_of(TEXT, st.none()), min_size=1, max_size=1))


@st.composite
def tasks(draw):
    """A few tasks of a few rows, over columns drawn from a shared pool (some tasks lack some)."""
    pool = [f"c{i}" for i in range(draw(st.integers(1, 5)))]
    out = []
    for _ in range(draw(st.integers(1, 3))):
        names = draw(st.lists(st.sampled_from(pool), min_size=1, unique=True))
        n = draw(st.integers(1, 3))
        kinds = {c: draw(COLUMN) for c in names}  # one strategy's draw per column and task
        rows = [{c: draw(st.sampled_from(kinds[c] + [kinds[c][0]])) for c in names}
                for _ in range(n)]
        if draw(st.booleans()):  # vary the column's values within the task
            for r in rows:
                for c in names:
                    r[c] = draw(st.sampled_from(draw(COLUMN)))
        out.append(rows)
    return out


def by_pandas(task_rows):
    texts, frames, names = [], [], {}
    for rows in task_rows:
        s = io.StringIO()
        pd.DataFrame.from_records(rows).to_csv(s, index=False, lineterminator="\n",
                                               float_format=float_formatter(TASK_FLOAT_FORMAT))
        texts.append(s.getvalue())
        frames.append(pd.read_csv(io.StringIO(s.getvalue())))
        names.update(dict.fromkeys(frames[-1].columns))
    out = io.StringIO()
    for i, f in enumerate(frames):
        f.reindex(columns=list(names)).to_csv(out, header=i == 0, index=False,
                                              float_format=float_formatter(), lineterminator="\n")
    return texts, out.getvalue()


@settings(max_examples=60, deadline=None)
@given(tasks())
def test_task_files_and_replications_csv_are_pandas_bytes(tmp_path_factory, task_rows):
    texts, assembled = by_pandas(task_rows)
    tmp = tmp_path_factory.mktemp("t")
    frames, names = [], {}
    for i, rows in enumerate(task_rows):
        write_task(rows, tmp / f"{i}.csv")
        text = (tmp / f"{i}.csv").read_text(encoding="utf-8")
        assert text == texts[i]
        data = read_task_text(text) or pd.read_csv(tmp / f"{i}.csv")
        frames.append(data)
        names.update(dict.fromkeys(data.header if hasattr(data, "header") else data.columns))
    out = io.StringIO()
    write_rows(frames, list(names), out)
    assert out.getvalue() == assembled


def test_the_usual_summary_rows_go_through_the_csv_module():
    """Rows as a sweep's tasks hold them (ints, floats, a NaN, names) take the fast path."""
    rows = [{"policy": "adaptive", "point": 0, "seed": 5, "replication": r, "x": 1.5 * r,
             "y": math.nan if r else 2.0, "name": "thesis"} for r in range(3)]
    text = task_csv(rows, TASK_FLOAT_FORMAT)
    assert text is not None and text.splitlines()[1] == "adaptive,0,5,0,0.0,2.0,thesis"
    data = read_task_text(text)
    assert data is not None and data.kinds == ["str", "int", "int", "int", "float", "float", "str"]
    assert data.values("replication") == [0, 1, 2] and math.isnan(data.values("y")[1])
