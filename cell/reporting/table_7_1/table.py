"""Table 7.1 beside the thesis (thesis §7.2; docs/accounting.md): part of a sweep's report.

For a sweep laid out like Table 7.1 (see :func:`is_table_7_1`), the report
(:mod:`cell.reporting.experiment.report`, ``cell sweep ... --report DIR``) holds, beside its
general files, the two that :func:`table_7_1_files` makes:

- ``table_7_1.csv``: long form, one row per (policy, ideal cycle, accounting,
  measure): the published value, the mean over replications with its 95 %
  confidence interval (Student t, scipy.stats), and the 2.5 and 97.5
  percentiles of single runs: the range a single 500-part run such as the
  thesis's should fall in.
- ``table_7_1.md``: the table in the thesis's layout with ours beside it, the
  adaptive results, and a reading generated from the numbers.

Two accountings of the same runs (docs/accounting.md): ``thesis`` reproduces the thesis's
bookkeeping, ``wallclock`` counts on the clock of a physically consistent cell.

What the thesis published for each policy is data (:data:`cell.reporting.published.PUBLISHED`):
a policy published row by row (Table 7.1) gets the thesis's table beside ours, one
published as a single run gets one row; :data:`LAYOUTS` maps each policy to its
published figures, its tables and its reading.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from cell.experiments.stats import summarise
from cell.experiments.sweep.results import runs_of
from cell.plumbing.errors import CellError
from cell.reporting import published
from cell.reporting.formatting import half_width, table_head, table_row
from cell.reporting.run_summary import is_thesis_cell
from cell.reporting.table_7_1.sentences import (
    ACCOUNTINGS,
    LABELS,
    MEASURES,
    inside,
    memoryless,
    reading_by_cycle,
    reading_one_run,
    row_of,
    thesis_value,
)
from cell.scenario import catalog
from cell.scenario.run_length import RunLength
from cell.scenario.schema import load_scenario

if TYPE_CHECKING:
    from cell.experiments.sweep import Sweep
    from cell.scenario.schema import Scenario

COLUMNS = ["policy", "ideal_cycle_s", "accounting", "measure", "thesis",
           "mean", "ci_low", "ci_high", "run_p2_5", "run_p97_5"]
#: The policies the thesis published figures for, in the report's order.
POLICIES = tuple(published.PUBLISHED)
CONFIDENCE = 0.95
VARIED_KEY = "controller.ideal_cycle_s"
DECIMALS = {"actual_cycle_s": 2, "parts_missed": 1, "parts_per_hr": 1,
            "vavg_r4_in_s": 4, "ip": 4}
__all__ = ["ACCOUNTINGS", "COLUMNS", "LABELS", "LAYOUTS", "MEASURES", "inside", "is_table_7_1",
           "markdown", "reading", "statistics", "summary_column", "table_7_1", "table_7_1_files",
           "thesis_value", "memoryless"]


def summary_column(accounting: str, measure: str, columns: Sequence[str]) -> str:
    """The summary column holding ``measure`` under ``accounting`` (the simulation's names).

    A measure both accountings share (Vavg R IV; parts missed unless the
    simulation splits it) is read from its one column.
    """
    candidates = {
        "actual_cycle_s": [f"actual_cycle_{accounting}_s"],
        "parts_missed": [f"parts_missed_{accounting}", "parts_missed"],
        "parts_per_hr": [f"parts_per_hr_{accounting}"],
        "vavg_r4_in_s": [f"vavg_r4_{accounting}_in_s", "vavg_r4_in_s"],
        "ip": [f"ip_{accounting}"],
    }[measure]
    for name in candidates:
        if name in columns:
            return name
    raise CellError(f"replications have no column {candidates[0]!r} for {measure} "
                    f"({accounting} accounting)")


def fixed_cycle(s: Scenario) -> float:
    """The non-adaptive robot's cycle in ``s``, as ``cell run`` runs it (a Table 7.1 row's,
    Fig. 23/24's): ``controller.ideal_cycle_s``, else the nominal cycle
    (:func:`cell.sim.policy_setup.nominal_cycle`: the arrivals' mean when the scenario sets none)."""
    from cell.sim.policy_setup import nominal_cycle

    c = s.controller.ideal_cycle_s
    return float(c) if c is not None else nominal_cycle(s)


def is_table_7_1(sweep: Sweep) -> bool:
    """Whether the sweep can be laid out as Table 7.1, beside the thesis's figures: it
    varies at most the robot cycle, runs only policies the thesis published figures for, a
    fixed number of times, on the thesis's own cell (any robot timing:
    :func:`~cell.reporting.run_summary.is_thesis_cell`)."""
    if not (set(sweep.keys) <= {VARIED_KEY} and sweep.precision is None
            and all(p.policy in published.PUBLISHED for p in sweep.points)):
        return False
    baseline = load_scenario("baseline")  # once, for every point
    return all(is_thesis_cell(p.scenario, any_timing=True, baseline=baseline)
               for p in sweep.points)


def statistics(values: Sequence[float] | np.ndarray) -> dict[str, float]:
    """Mean, its t confidence interval and the 2.5/97.5 percentiles of single runs
    (:func:`cell.experiments.stats.summarise`); one run: a zero-width interval."""
    x = np.asarray(values, dtype=float)
    s = summarise(x[np.isfinite(x)], CONFIDENCE)
    if s["n"] == 1:
        s["ci_low"] = s["ci_high"] = s["mean"]
    return {k: s[k] for k in ("mean", "ci_low", "ci_high", "run_p2_5", "run_p97_5")}


def table_7_1(replications: pd.DataFrame, sweep: Sweep) -> pd.DataFrame:
    """The long-form table: one row per (policy, ideal cycle, accounting, measure)."""
    rows = []
    order = sorted(range(len(sweep.points)),
                   key=lambda i: (POLICIES.index(sweep.points[i].policy), i))
    for i in order:
        p = sweep.points[i]
        runs = runs_of(replications, sweep, i)
        cycle = fixed_cycle(p.scenario)
        for accounting in ACCOUNTINGS:
            for measure in MEASURES:
                column = summary_column(accounting, measure, list(replications.columns))
                rows.append({"policy": p.policy, "ideal_cycle_s": cycle,
                             "accounting": accounting, "measure": measure,
                             "thesis": thesis_value(p.policy, cycle, accounting, measure),
                             **statistics(runs[column].to_numpy(dtype=float))})
    return pd.DataFrame(rows, columns=COLUMNS)


# --------------------------------------------------------------------------- markdown
def _fmt(value: float, measure: str, decimals: int | None = None) -> str:
    if not math.isfinite(value):
        return ""
    return f"{value:.{DECIMALS[measure] if decimals is None else decimals}f}"


def _ours(row: Mapping[str, Any], measure: str) -> str:
    half = half_width(row)
    lo_hi = (f"{_fmt(row['run_p2_5'], measure, 0 if measure == 'parts_missed' else None)}–"
             f"{_fmt(row['run_p97_5'], measure, 0 if measure == 'parts_missed' else None)}")
    mark = ""
    thesis = row["thesis"]
    if math.isfinite(thesis) and not inside(thesis, row["run_p2_5"], row["run_p97_5"], measure):
        mark = " †"
    return f"{_fmt(row['mean'], measure)} ± {_fmt(half, measure)} [{lo_hi}]{mark}"


def _layout(table: pd.DataFrame, policy: str, accounting: str, with_thesis: bool) -> list[str]:
    sub = table[(table["policy"] == policy) & (table["accounting"] == accounting)]
    head = ["ideal cycle (s)"]
    for m in MEASURES:
        head += [f"{LABELS[m]}: thesis", "ours"] if with_thesis else [LABELS[m]]
    lines = table_head(head)
    for cycle, group in sub.groupby("ideal_cycle_s", sort=False):
        by: dict[str, Mapping[str, Any]] = {str(r["measure"]): {str(k): v for k, v in r.items()}
                                            for r in group.to_dict("records")}
        cells = [f"{cycle:.4f}"]
        for m in MEASURES:
            if with_thesis:
                cells.append(_fmt(by[m]["thesis"], m, 4 if m != "parts_missed" else 0))
            cells.append(_ours(by[m], m))
        lines.append(table_row(cells))
    return lines


def reading(table: pd.DataFrame, parts: int | None,
            replications: pd.DataFrame | None = None) -> list[str]:
    """Sentences drawn from the numbers: agreement, where the accountings part, and why;
    each policy's by its layout (:data:`LAYOUTS`), in the thesis's order."""
    out: list[str] = []
    for policy in _present(table):
        out += LAYOUTS[policy].reading(table, policy, parts, replications)
    return out


def _present(table: pd.DataFrame) -> list[str]:
    """The published policies the table holds, in the thesis's order."""
    held = set(table["policy"])
    return [p for p in POLICIES if p in held]


def markdown(table: pd.DataFrame, sweep: Sweep, replications: pd.DataFrame | None = None) -> str:
    run = sweep.points[0].scenario.run if sweep.points else None
    length = RunLength.of(run) if run is not None else None
    parts = run.parts if run is not None and run.hours is None else None  # the parts a run brings
    lines = [
        "# Table 7.1 regenerated (thesis §7.2)",
        "",
        f"Generated by `cell sweep {catalog.shown(sweep.source)} --report ...` from "
        f"{sweep.replications} replications of {length} per row, root seed {sweep.seed}; "
        "every row and both policies see the same arrivals (common random numbers). "
        "Numbers: our mean ± half-width of its 95 % confidence interval (Student t), "
        "[the 2.5–97.5 % range of single runs: where one run like the thesis's should fall]. "
        "† marks a published figure outside that range. "
        "Long form with every figure: `table_7_1.csv`.",
        "",
    ]
    for policy in _present(table):
        lines += LAYOUTS[policy].tables(table, policy)
    lines += ["## Reading", ""]
    for sentence in reading(table, parts, replications):
        lines += [sentence, ""]
    return "\n".join(lines).rstrip() + "\n"


def _by_cycle_tables(table: pd.DataFrame, policy: str) -> list[str]:
    """The thesis's table beside ours, then ours on the wall clock."""
    name = policy.capitalize()
    return [f"## {name}, the thesis's accounting (its Table 7.1 beside ours)", "",
            *_layout(table, policy, "thesis", with_thesis=True), "",
            f"## {name}, on the wall clock (a physically consistent count)", "",
            *_layout(table, policy, "wallclock", with_thesis=False), ""]


def _one_run_table(table: pd.DataFrame, policy: str) -> list[str]:
    """The published run's figures, then ours in both accountings."""
    lines = [f"## {policy.capitalize()} (thesis §7.2: {published.PUBLISHED[policy].summary})", ""]
    head = ["accounting"] + [LABELS[m] for m in MEASURES]
    lines += table_head(head)
    cycle = float(table.loc[table["policy"] == policy, "ideal_cycle_s"].iloc[0])
    published_cells = [_fmt(thesis_value(policy, cycle, "thesis", m), m,
                            0 if m == "parts_missed" else 4) for m in MEASURES]
    lines.append(table_row(["thesis (published)", *published_cells]))
    for accounting in ACCOUNTINGS:
        cells = [_ours(row_of(table, policy, cycle, accounting, m), m) for m in MEASURES]
        lines.append(table_row([f"ours, {accounting}", *cells]))
    return lines + [""]


@dataclass(frozen=True)
class Layout:
    """How one policy's part of the report is laid out: from what the thesis published."""

    published: published.Published
    tables: Callable[[pd.DataFrame, str], list[str]]
    reading: Callable[[pd.DataFrame, str, int | None, pd.DataFrame | None], list[str]]


def _layout_of(figures: published.Published) -> Layout:
    if figures.by_cycle:
        return Layout(figures, _by_cycle_tables, reading_by_cycle)
    return Layout(figures, _one_run_table, reading_one_run)


#: Policy -> its published figures, tables and reading.
LAYOUTS: Mapping[str, Layout] = {policy: _layout_of(figures)
                                 for policy, figures in published.PUBLISHED.items()}


def table_7_1_files(replications: pd.DataFrame, sweep: Sweep) -> tuple[pd.DataFrame, str]:
    """The long-form table and the markdown text, for ``table_7_1.csv`` and ``.md``."""
    table = table_7_1(replications, sweep)
    return table, markdown(table, sweep, replications)
