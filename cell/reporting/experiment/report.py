"""Any sweep's report: ``cell sweep SWEEP --report DIR`` and ``cell compare --out DIR``.

From a sweep's ``replications.csv`` (:mod:`cell.experiments.sweep.runner`) this writes, as
one unit (:class:`cell.plumbing.output.atomic.OutputDir`: the whole set appears at once or not
at all):

- ``summary.csv``: tidy long form, one row per (grid point, policy, measure) for
  every numeric column of the runs' summaries: the grid's columns, ``policy``,
  ``measure``, ``n``, ``mean``, ``sd``, the confidence interval of the mean
  ``ci_low``/``ci_high`` (Student t) and ``run_p2_5``/``run_p97_5``, where
  95 % of single runs fall (:func:`cell.experiments.stats.summarise`);
- ``differences.csv``: the paired comparisons of :meth:`cell.experiments.sweep.Sweep.pairs`
  -- replication r of both points drew the same parts (common random numbers),
  so the difference is taken replication by replication: the grid's columns,
  ``policy``, ``versus``, ``measure``, ``n``, ``mean``, ``sd``, ``ci_low``,
  ``ci_high``, ``p_value`` (:func:`cell.experiments.stats.paired_difference`);
- ``report.md``: a table, a figure and the paired differences per headline
  measure (:mod:`cell.reporting.formatting`), and a reading drawn from the numbers
  (:mod:`cell.reporting.experiment.text`);
- ``fig_<measure>.png`` per headline measure (:mod:`cell.reporting.experiment.plots`);
- for a sweep laid out like Table 7.1, ``table_7_1.csv`` and ``table_7_1.md``
  (:mod:`cell.reporting.table_7_1`), linked from ``report.md``.

A ``--report DIR`` that already holds files the report does not write (a shared
folder such as the repository's ``reports/``), or will hold the sweep's own
``--out``, is left as it is: the whole set goes to ``DIR/<sweep name>/``.  If
``DIR/<sweep name>/`` would itself be, or hold, ``--out``, the sweep is refused
before it runs.
"""

from __future__ import annotations

import fnmatch
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from cell.experiments.sweep import Sweep
from cell.experiments.sweep.windows import window_warning
from cell.plumbing.errors import CellError
from cell.plumbing.output.atomic import OutputDir
from cell.reporting.experiment.data import difference_table, measures, summary_table
from cell.reporting.experiment.plots import figures
from cell.reporting.experiment.text import markdown
from cell.reporting.table_7_1.table import is_table_7_1, table_7_1_files

REPORT_FILES = ("report.md", "summary.csv", "differences.csv", "fig_*.png")
TABLE_7_1_FILES = ("table_7_1.csv", "table_7_1.md")
__all__ = ["Target", "difference_table", "measures", "plan_report", "summary_table",
           "write_report"]


@dataclass(frozen=True)
class Target:
    """Where a report goes: the unit's directory and files, and whether Table 7.1's
    two files are among them."""

    directory: Path
    names: tuple[str, ...]
    table_7_1: bool


def plan_report(sweep: Sweep, target: str | os.PathLike[str], option: str = "--report",
                results: str | os.PathLike[str] | None = None) -> Target:
    """Check, before anything runs, where the report can go (see the module's docstring);
    ``results``: the sweep's ``--out``, which makes a folder holding it a shared one."""
    t71 = is_table_7_1(sweep)
    names = REPORT_FILES + (TABLE_7_1_FILES if t71 else ())
    path = Path(target)
    if not (_holds(path, results) or _shared(path, names)):
        OutputDir.check(path, names, option)
        return Target(path, names, t71)
    sub = path / (re.sub(r"[^\w.-]+", "_", sweep.name).strip("._") or "sweep")
    if _holds(sub, results):
        raise CellError(f"{option} {target}: the report would go to {sub}, which is or holds "
                        f"--out {results}, the sweep's own results; choose another {option} "
                        "or --out")
    OutputDir.check(sub, names, option)
    return Target(sub, names, t71)


def _holds(path: Path, results: str | os.PathLike[str] | None) -> bool:
    """Whether the folder ``path`` is, or holds, the folder ``results``, either reached
    through symbolic links: compared where they lead."""
    if results is None:
        return False
    mine, theirs = Path(path).resolve(), Path(results).resolve()
    return mine == theirs or mine in theirs.parents


def _shared(path: Path, names: Sequence[str]) -> bool:
    """Whether ``path`` is a directory holding entries the report does not write."""
    try:
        entries = [e.name for e in os.scandir(path)]
    except OSError:
        return False
    return any(not e.startswith(".") and not any(fnmatch.fnmatchcase(e, n) for n in names)
               for e in entries)


def write_report(replications: pd.DataFrame, sweep: Sweep, target: Target,
                 command: str, caveat: str | None = None,
                 tables: tuple[pd.DataFrame, pd.DataFrame] | None = None) -> list[Path]:
    """Write the report (see the module's docstring); return the paths written.
    A target that names ``replications.csv`` gets the replications too.  ``tables``:
    the summary and difference tables if already made from these replications.
    ``caveat`` opens report.md; by default the sweep's window warning, if it has one
    (:func:`cell.experiments.sweep.windows.window_warning`)."""
    if caveat is None:
        caveat = window_warning(sweep)
    summary, differences = tables or (summary_table(replications, sweep),
                                      difference_table(replications, sweep))
    pngs = figures(summary, replications, sweep)
    text = markdown(summary, differences, replications, sweep, command, list(pngs), caveat,
                    target.table_7_1)
    written = []
    with OutputDir(target.directory, target.names, "--report") as out:
        out.write_text("report.md", text)
        out.write_csv("summary.csv", summary)
        out.write_csv("differences.csv", differences)
        for name, data in pngs.items():
            with out.open(name, "wb") as fh:
                fh.write(data)
        written = ["report.md", "summary.csv", "differences.csv", *pngs]
        if "replications.csv" in target.names:
            out.write_csv("replications.csv", replications)
            written.append("replications.csv")
        if target.table_7_1:
            table, t71_text = table_7_1_files(replications, sweep)
            out.write_csv("table_7_1.csv", table)
            out.write_text("table_7_1.md", t71_text)
            written += list(TABLE_7_1_FILES)
    return [target.directory / name for name in written]

