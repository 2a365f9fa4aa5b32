"""Replicated sweeps over scenario keys: ``cell sweep`` (thesis §6.3, §7.2).

:mod:`cell.sweep.spec` reads and checks a sweep file; :mod:`cell.sweep.runner`
runs its tasks (locally or on a dask cluster, resumable) into
``replications.csv``.
"""

from cell.sweep.runner import Outcome, Replicate, run_sweep, simulate_summary
from cell.sweep.spec import Point, Sweep, Task, load_sweep

__all__ = ["Outcome", "Point", "Replicate", "Sweep", "Task", "load_sweep", "run_sweep",
           "simulate_summary"]
