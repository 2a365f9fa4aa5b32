"""The hindsight optimum of a run (docs/model.md, "The hindsight optimum"): for the parts a run
of the scenario sees, the most any feasible schedule could deliver, between a schedule run
through the simulation (:mod:`.search`) and a proved upper bound (:mod:`.milp`).

:func:`hindsight` draws the run's arrivals as ``cell run`` does (the same seed, the same code),
solves the MILP within the time budget when the run is small enough, and runs the search's
schedules (greedy; following the MILP's schedule three ways) through the simulation, beside the
built-in controllers' own runs (schedules too), the best kept.  ``exact`` is true when that
schedule reaches the proved bound: then it is the optimum.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cell.experiments.hindsight.milp import MilpResult, solve
from cell.experiments.hindsight.search import SPEED_STEPS, Targets, run_schedule
from cell.plumbing.errors import ScenarioError
from cell.scenario.schema import Scenario
from cell.sim.assembly import assemble
from cell.sim.bound import parts_bound
from cell.sim.horizon import run_arrivals
from cell.sim.records import PartRecord
from cell.sim.simulation import SimResult, simulate

#: The built-in controllers, whose own runs are schedules the search keeps if they are best.
BUILT_IN = ("adaptive", "non-adaptive")
#: The longest run the MILP is tried on (parts): its binaries grow about fivefold with them.
MILP_MAX_PARTS = 60
#: The share of the budget the MILP may take; the search's schedules have the rest.
MILP_SHARE = 0.8

SUMMARY_COLUMNS = ("scenario", "seed", "parts", "warmup_parts", "parts_optimum", "exact",
                   "parts_upper", "parts_bound", "upper_from", "milp_status", "milp_parts",
                   "milp_binaries", "search", "speed_steps", "budget_s")
#: Wall-clock seconds the MILP and the search took: told, not written (a CSV of the same
#: scenario and seed is the same file, byte for byte, however busy the machine).
TIMING_KEYS = ("solve_s", "search_s")
SCHEDULE_COLUMNS = ("part", "arrival_s", "picked", "at_b_s", "pick_s", "touchdown_s",
                    "input_speed_in_s", "motion_cycle_s", "milp_picked", "milp_at_b_s")


@dataclass
class Hindsight:
    """One run's hindsight: the summary's values and the schedule's rows."""

    summary: dict[str, Any]
    schedule: list[tuple[Any, ...]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    """What the user should be told (the MILP too large, stopped at the budget)."""


def check(s: Scenario) -> None:
    """Refuse a scenario the hindsight does not cover (one line, its key and value)."""
    if s.failures is not None:
        raise ScenarioError(s.source, "failures", "(a section)",
                            "the hindsight optimum is for a cell without failures; "
                            "remove the failures section")
    if s.run.hours is not None:
        raise ScenarioError(s.source, "run.hours", s.run.hours,
                            "the hindsight optimum needs a run of run.parts parts")
    if s.run.warmup_parts == "auto":
        raise ScenarioError(s.source, "run.warmup_parts", "auto",
                            "the hindsight optimum needs a warm-up in parts (an integer)")


def hindsight(s: Scenario, budget_s: float) -> Hindsight:
    """The hindsight optimum of the run of ``s`` (its ``run.seed``), within ``budget_s``."""
    check(s)
    started = time.perf_counter()
    cell = assemble(s)
    t, n, _ = run_arrivals(s, s.run.seed)
    come = np.cumsum(t)[:n].tolist()
    w = min(int(s.run.warmup_parts), n)
    bound = parts_bound(cell.k, come[w:])
    notes: list[str] = []
    milp = _milp(cell.k, come, w, budget_s, notes)
    searched = time.perf_counter()
    best_name, best = _search(s, cell, come, milp, started + budget_s, notes)
    assert best.records is not None
    found = int(best.summary.parts_delivered)
    upper, upper_from = (milp.upper, "milp") if milp.upper is not None else (bound, "parts_bound")
    upper = min(upper, bound)
    summary = {
        "scenario": s.name, "seed": s.run.seed, "parts": n, "warmup_parts": w,
        "parts_optimum": found, "exact": found == upper, "parts_upper": upper,
        "parts_bound": bound, "upper_from": upper_from, "milp_status": milp.status,
        "milp_parts": milp.count if milp.picked else math.nan, "milp_binaries": milp.binaries,
        "search": best_name, "speed_steps": SPEED_STEPS, "budget_s": budget_s,
        "solve_s": milp.solve_s, "search_s": time.perf_counter() - searched}
    return Hindsight(summary, _rows(best.records, milp), notes)


def _milp(k: Any, come: list[float], warmup: int, budget_s: float,
          notes: list[str]) -> MilpResult:
    """The MILP's answer within its share of the budget, or ``too_large`` (a note says so)."""
    n = len(come)
    if n > MILP_MAX_PARTS:
        notes.append(f"the MILP is too large for {n} parts (at most {MILP_MAX_PARTS}): the "
                     "feasible search's result is given, exact=false, against parts_bound")
        return MilpResult("too_large", None)
    limit = budget_s * MILP_SHARE
    milp = solve(k, come, warmup, limit)
    if milp.status == "time_limit":
        notes.append(f"the MILP stopped at its time limit ({limit:g} s): its bound is "
                     f"{milp.upper} parts, not proved tight")
    elif milp.status == "failed":
        notes.append("the MILP gave no answer within its time limit: the bound is parts_bound")
    return milp


def _search(s: Scenario, cell: Any, come: list[float], milp: MilpResult, deadline: float,
            notes: list[str]) -> tuple[str, SimResult]:
    """The best of the search's schedules run through the simulation (the greedy one always
    runs; the others while the budget lasts), a built-in controller's own run among them."""
    n = len(come)
    tries: list[tuple[str, Targets | str | None]] = [("greedy", None)]
    if milp.picked:
        tries += [("milp", Targets(milp.picked, milp.at_b_s, milp.drop_in)),
                  ("milp_times", Targets(milp.picked, milp.at_b_s)),
                  ("milp_soonest", Targets(milp.picked, [-math.inf] * n))]
    tries += [(name, name) for name in BUILT_IN]
    best_name, best = "", None
    for name, targets in tries:
        if best is not None and time.perf_counter() > deadline:
            notes.append(f"the budget ran out before the search's {name} schedule")
            break
        if isinstance(targets, str):  # a built-in controller's own run: a schedule too
            result = simulate(s.with_overrides({"controller.policy": targets}), s.run.seed)
        else:
            result = run_schedule(s, cell, come, s.run.seed, targets)
        if best is None or result.summary.parts_delivered > best.summary.parts_delivered:
            best_name, best = name, result
    assert best is not None
    return best_name, best


def _rows(records: list[PartRecord], milp: MilpResult) -> list[tuple[Any, ...]]:
    """The schedule's rows: each part as the search's run had it, beside the MILP's."""
    rows = []
    for r in records:
        i = r.part - 1
        rows.append((r.part, r.arrival_s, bool(r.picked), r.at_bot_s, r.pick_s, r.touchdown_s,
                     r.input_speed_in_s, r.motion_cycle_s,
                     bool(milp.picked[i]) if milp.picked else "",
                     milp.at_b_s[i] if milp.picked else math.nan))
    return rows
