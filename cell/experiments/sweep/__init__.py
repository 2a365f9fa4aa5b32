"""Replicated sweeps over scenario keys: ``cell sweep`` (thesis §6.3, §7.2).

:mod:`cell.experiments.sweep.spec` reads and checks a sweep file (:mod:`cell.experiments.sweep.options`:
replications to a precision, the baseline); :mod:`cell.experiments.sweep.runner` runs its
tasks (locally or on a dask cluster, resumable) into ``replications.csv``, whose
grid columns :mod:`cell.experiments.sweep.columns` lays out, in the ``--out`` directory that
:mod:`cell.experiments.sweep.outdir` checks and prepares.
"""

from cell.experiments.sweep.columns import Column, grid_columns, point_values
from cell.experiments.sweep.runner import Outcome, Replicate, run_sweep, simulate_summary
from cell.experiments.sweep.spec import (
    Baseline,
    Pair,
    Point,
    Precision,
    Sweep,
    Task,
    load_sweep,
    summary_measures,
)

__all__ = ["Baseline", "Column", "Outcome", "Pair", "Point", "Precision", "Replicate", "Sweep",
           "Task", "grid_columns", "load_sweep", "point_values", "run_sweep", "simulate_summary",
           "summary_measures"]
