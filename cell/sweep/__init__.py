"""Replicated sweeps over scenario keys: ``cell sweep`` (thesis §6.3, §7.2).

:mod:`cell.sweep.spec` reads and checks a sweep file (:mod:`cell.sweep.options`:
replications to a precision, the baseline); :mod:`cell.sweep.runner` runs its
tasks (locally or on a dask cluster, resumable) into ``replications.csv``, whose
grid columns :mod:`cell.sweep.columns` lays out, in the ``--out`` directory that
:mod:`cell.sweep.outdir` checks and prepares.
"""

from cell.sweep.columns import Column, grid_columns, point_values
from cell.sweep.runner import Outcome, Replicate, run_sweep, simulate_summary
from cell.sweep.spec import (
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
