"""The numbers of an experiment's report: ``summary.csv`` and ``differences.csv``
(:mod:`cell.reporting.experiment.report`), from a sweep's ``replications.csv``.

Every interval comes from :mod:`cell.experiments.stats` (Student t, scipy.stats):
:func:`~cell.experiments.stats.summarise` per point, and
:func:`~cell.experiments.stats.paired_difference` per pair of points, replication r
against replication r (common random numbers).
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Sequence

import numpy as np
import pandas as pd

from cell.experiments.stats import PAIRED_KEYS, SUMMARY_KEYS, paired_many, summarise_many
from cell.experiments.sweep import Column, Pair, Sweep, grid_columns
from cell.experiments.sweep.windows import pair_apart, window_measures

#: Columns of replications.csv that are not measures.
NOT_MEASURES = {"policy", "point", "seed", "replication"}
#: The share of the bound a run delivered, in percent: its ``parts_delivered`` over its
#: ``parts_bound`` (:mod:`cell.sim.bound`, the most any controller could deliver from the same
#: arrivals), run by run, so its mean has an interval over the replications and two policies'
#: shares a paired difference; a run whose bound is 0 has none.
BOUND_SHARE = "delivered_of_bound_pct"
#: Parts lost on the wall clock as a share of the parts arrived, in percent, run by run: the
#: measure ``cell optimize`` and the studies report by this name
#: (:func:`cell.experiments.study.parts_missed_pct`, the one rule of both).
MISSED_SHARE = "parts_missed_pct"


def measures(replications: pd.DataFrame, sweep: Sweep) -> list[str]:
    """The numeric columns of the runs' summaries, in their order."""
    grid = {c.name for c in grid_columns(sweep)}
    return [c for c in replications.columns
            if c not in NOT_MEASURES and c not in grid
            and pd.api.types.is_numeric_dtype(replications[c])]


def with_shares(replications: pd.DataFrame) -> pd.DataFrame:
    """``replications`` with the run-by-run shares a report summarises beside the runs'
    measures: :data:`MISSED_SHARE`, then :data:`BOUND_SHARE`, last."""
    return with_bound_share(with_missed_share(replications))


def with_missed_share(replications: pd.DataFrame) -> pd.DataFrame:
    """``replications`` with :data:`MISSED_SHARE` after its other columns, if its runs count
    parts lost and arrived (the frame itself otherwise, and if the share is already there)."""
    from cell.experiments.study import parts_missed_pct

    if MISSED_SHARE in replications.columns or \
            not {"parts_missed", "parts_arrived"} <= set(replications.columns):
        return replications
    return replications.assign(**{MISSED_SHARE: parts_missed_pct(
        replications["parts_missed"], replications["parts_arrived"])})


def with_bound_share(replications: pd.DataFrame) -> pd.DataFrame:
    """``replications`` with :data:`BOUND_SHARE` after its other columns, if its runs have a
    bound (the frame itself otherwise, and if the share is already there)."""
    have = replications.columns
    if BOUND_SHARE in have or not {"parts_delivered", "parts_bound"} <= set(have):
        return replications
    bound = replications["parts_bound"].to_numpy(float)
    with np.errstate(divide="ignore", invalid="ignore"):
        share = np.where(bound > 0, 100.0 * replications["parts_delivered"].to_numpy(float)
                         / bound, np.nan)
    return replications.assign(**{BOUND_SHARE: share})


def grid_values(runs: pd.DataFrame, columns: Sequence[Column]) -> dict[str, object]:
    """A point's value in each grid column, as its ``runs`` (:func:`runs_of`) hold it."""
    first = runs.iloc[0] if len(runs) else None
    return {c.name: (None if first is None else _plain(first[c.name])) for c in columns}


def _plain(value: object) -> object:
    return value.item() if hasattr(value, "item") else value


class _Rows:
    """Each point's rows of ``replications`` (positions, in replication order, as
    :func:`runs_of` gives them) and each column as one array, found once for all points.
    Slicing the frame point by point and summarising one measure at a time cost a point of
    41 measures 12.8 ms for ``summary.csv`` and 13.1 ms for ``differences.csv`` (CPU time,
    100 points of 2 replications); with this and :func:`~cell.experiments.stats.summarise_many`
    and :func:`~cell.experiments.stats.paired_many`, 1.5 and 1.1 ms (``cell bench``,
    ``sweep_overhead_ms_per_point``)."""

    def __init__(self, replications: pd.DataFrame, sweep: Sweep):
        self.frame = replications
        self._arrays: dict[str, np.ndarray] = {}
        groups = replications.groupby(["policy", "point"], sort=False).indices
        reps = replications["replication"].to_numpy()
        self.at: list[np.ndarray] = []
        for p in sweep.points:
            idx = np.asarray(groups.get((p.policy, p.index), []), dtype=np.intp)
            self.at.append(idx[np.argsort(reps[idx], kind="stable")])

    def column(self, name: str) -> np.ndarray:
        if name not in self._arrays:
            self._arrays[name] = self.frame[name].to_numpy()
        return self._arrays[name]

    def values(self, i: int, name: str) -> np.ndarray:
        return self.column(name)[self.at[i]].astype(float)

    def grid(self, i: int, columns: Sequence[Column]) -> dict[str, object]:
        """As :func:`grid_values` of the point's runs."""
        first = self.at[i][0] if len(self.at[i]) else None
        return {c.name: None if first is None else _plain(self.column(c.name)[first])
                for c in columns}


def run_counts(replications: pd.DataFrame, sweep: Sweep) -> list[int]:
    """Each point's number of replications (``len(runs_of(...))`` of each, found at once)."""
    return [len(at) for at in _Rows(replications, sweep).at]


def summary_table(replications: pd.DataFrame, sweep: Sweep) -> pd.DataFrame:
    """``summary.csv``: every point, policy and measure with its statistics (the runs'
    measures, then :data:`MISSED_SHARE` and, last, :data:`BOUND_SHARE`)."""
    replications = with_shares(replications)
    columns, names = grid_columns(sweep), measures(replications, sweep)
    rows = []
    found = _Rows(replications, sweep)
    stats = iter(summarise_many([found.values(i, m) for i in range(len(sweep.points))
                                 for m in names], sweep.confidence))
    for i, p in enumerate(sweep.points):
        keys = found.grid(i, columns)
        for m in names:
            rows.append({**keys, "policy": p.policy, "measure": m, **next(stats)})
    return pd.DataFrame(rows, columns=[*(c.name for c in columns), "policy", "measure",
                                       *SUMMARY_KEYS])


def all_pairs(sweep: Sweep) -> list[Pair]:
    """The sweep's paired comparisons (:meth:`Sweep.pairs`: against its ``baseline:`` if
    it names one) and, with a baseline, the policies' against each other as well: naming
    a baseline adds its comparison to theirs."""
    pairs = sweep.pairs()
    if sweep.baseline is None:
        return pairs
    seen = {(p.point, p.versus) for p in pairs}
    return pairs + [p for p in dataclasses.replace(sweep, baseline=None).pairs()
                    if (p.point, p.versus) not in seen]


def difference_table(replications: pd.DataFrame, sweep: Sweep) -> pd.DataFrame:
    """``differences.csv``: each pair of points, replication by replication, per measure.

    The grid columns hold the compared point's values, or its partner's for a key
    only the partner varies.  A pair whose points run over different windows
    (:mod:`cell.experiments.sweep.windows`) has no rows for the counts and extremes.
    """
    replications = with_shares(replications)
    columns, names = grid_columns(sweep), measures(replications, sweep)
    windowed = set(window_measures())
    rows: list[dict[str, object]] = []
    samples: list[tuple[np.ndarray, np.ndarray]] = []
    found = _Rows(replications, sweep)
    reps = found.column("replication")
    for pair in all_pairs(sweep):
        compared = [m for m in names if m not in windowed] if pair_apart(sweep, pair) else names
        a, b = sweep.points[pair.point], sweep.points[pair.versus]
        mine, theirs = found.grid(pair.point, columns), found.grid(pair.versus, columns)
        keys = {c.name: theirs[c.name] if c.key in dict(b.values) and c.key not in dict(a.values)
                else mine[c.name] for c in columns}
        at_a, at_b = found.at[pair.point], found.at[pair.versus]  # the replications both ran
        _, ia, ib = np.intersect1d(reps[at_a], reps[at_b], assume_unique=True,
                                   return_indices=True)
        for m in compared:
            samples.append((found.values(pair.point, m)[ia], found.values(pair.versus, m)[ib]))
            rows.append({**keys, "policy": a.policy, "versus": pair.label, "measure": m})
    with warnings.catch_warnings():  # nearly equal pairs: scipy warns, the sd says it
        warnings.filterwarnings("ignore", "Precision loss", RuntimeWarning)
        for row, d in zip(rows, paired_many(samples, sweep.confidence), strict=True):
            row.update(d)
    return pd.DataFrame(rows, columns=[*[c.name for c in columns], "policy", "versus", "measure",
                                       *PAIRED_KEYS])
