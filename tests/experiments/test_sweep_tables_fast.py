"""summary.csv and differences.csv made at once for all points (cell.reporting.experiment.data,
cell.experiments.stats.summarise_many) hold the figures the point-by-point way gives, bit for bit:
each point's runs sliced from the frame, summarised and paired one by one."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
from hypothesis import given, settings
from hypothesis import strategies as st

from cell.experiments.stats import paired_difference, paired_many, summarise, summarise_many
from cell.experiments.sweep import grid_columns, load_sweep, run_sweep
from cell.experiments.sweep.results import runs_of
from cell.reporting.experiment.data import (
    all_pairs,
    difference_table,
    grid_values,
    measures,
    summary_table,
)

VALUES = st.lists(st.one_of(st.floats(-1e6, 1e6), st.just(float("nan")), st.just(3.0)),
                  max_size=12)


@settings(max_examples=60, deadline=None)
@given(st.lists(VALUES, max_size=8))
def test_summarise_many_is_summarise_of_each(arrays):
    got = summarise_many([np.array(a, dtype=float) for a in arrays])
    want = [summarise(np.array(a, dtype=float)) for a in arrays]
    assert len(got) == len(want)
    for g, w in zip(got, want, strict=True):
        assert list(g) == list(w)
        assert np.array_equal(list(g.values()), list(w.values()), equal_nan=True), (g, w)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(0, 12).flatmap(lambda n: st.tuples(
    st.lists(st.one_of(st.floats(-1e3, 1e3), st.just(float("nan")), st.just(2.0)),
             min_size=n, max_size=n),
    st.lists(st.one_of(st.floats(-1e3, 1e3), st.just(2.0)), min_size=n, max_size=n))),
    max_size=8))
def test_paired_many_is_paired_difference_of_each(pairs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        got = paired_many([(np.array(a), np.array(b)) for a, b in pairs])
        want = [paired_difference(np.array(a), np.array(b)) for a, b in pairs]
    assert len(got) == len(want)
    for g, w in zip(got, want, strict=True):
        assert list(g) == list(w)
        assert np.array_equal(list(g.values()), list(w.values()), equal_nan=True), (g, w)


def lumpy(scenario, seed) -> dict:
    """Spread that depends on the point, a measure now and then undefined (NaN)."""
    rng = np.random.default_rng(seed)
    v = scenario.belts.output_nominal_in_s
    z = rng.standard_normal(3)
    adaptive = scenario.controller.policy == "adaptive"
    return {"a": 100 * v + z[0] * v, "b": float("nan") if z[1] > 1 else z[1] + adaptive,
            "c": 7, "d": 1.0 + 1e-13 * z[2]}


def test_the_tables_are_the_point_by_point_ones(sweeps, tmp_path):
    path = sweeps.write(tmp_path, grid={"belts.output_nominal_in_s": [1.8, 2.0, 2.2]},
                        policies=["non-adaptive", "adaptive"], replications=7, batch=3,
                        baseline={"policy": "non-adaptive", "belts.output_nominal_in_s": 2.0})
    sweep = load_sweep(path)
    frame = run_sweep(sweep, tmp_path / "o", workers=1, replicate=lumpy,
                      progress=False).replications
    frame = frame.sample(frac=1, random_state=3)  # rows in any order
    columns, names = grid_columns(sweep), measures(frame, sweep)
    rows = []
    for i, p in enumerate(sweep.points):
        runs = runs_of(frame, sweep, i)
        rows += [{**grid_values(runs, columns), "policy": p.policy, "measure": m,
                  **summarise(runs[m].to_numpy(dtype=float))} for m in names]
    pd.testing.assert_frame_equal(summary_table(frame, sweep),
                                  pd.DataFrame(rows).astype(summary_table(frame, sweep).dtypes),
                                  check_exact=True)
    rows = []
    for pair in all_pairs(sweep):
        ra, rb = runs_of(frame, sweep, pair.point), runs_of(frame, sweep, pair.versus)
        both = ra.merge(rb, on="replication", suffixes=("", "@b"))
        for m in names:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                rows.append(paired_difference(both[m].to_numpy(float), both[m + "@b"].to_numpy(float)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        got = difference_table(frame, sweep)
    assert len(got) == len(rows)
    want = pd.DataFrame(rows)
    for c in want.columns:
        assert np.array_equal(got[c].to_numpy(float), want[c].to_numpy(float), equal_nan=True), c
