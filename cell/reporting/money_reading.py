"""The money reading of a study (docs/usage.md, "Energy and cost"): with the scenario's
``costs:``, what each option the study compares costs, and the cheapest way to a loss target.

A study gives one row per option (a sensor, a fixed cycle, a buffer size, ...), each over the
same stretch of production (a 500-part run, a year), with the columns of :data:`INPUTS`:

- ``lost``: parts lost (ridden off, or scrapped from the hand);
- ``good``: good parts (``quality.rule``, as OEE counts them);
- ``hours``: the time they took;
- ``down_h``: the robot's downtime, h;
- ``repairs`` and ``maintenance``: the stops (failures of any equipment; planned stops);
- ``energy_kwh``: the energy (0 without an ``energy:`` section);
- ``options_per_h``: the hourly cost of the options that option has
  (:func:`cell.sim.run_cost.options_per_h`).

Its cost is the same sum a run's is (:mod:`cell.sim.run_cost`): lost × ``part_value`` +
energy × ``energy_per_kwh`` + down_h × ``downtime_per_h`` + repairs × ``repair`` +
maintenance × ``maintenance`` + options_per_h × hours.  The cheapest way to a loss target is
the option with the lowest cost per good part among those losing at most the target.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd

#: The columns an option's row must have.
INPUTS = ("lost", "good", "hours", "down_h", "repairs", "maintenance", "energy_kwh", "options_per_h")
#: The inputs in the order :func:`cell.sim.run_cost.cost` takes them (then the hours).
TERMS = ("lost", "energy_kwh", "down_h", "repairs", "maintenance", "options_per_h")
#: The columns :func:`priced` adds.
OUTPUTS = ("cost", "cost_per_good_part", "cost_per_h")


def run_inputs(runs: pd.DataFrame, scenario: Any) -> dict[str, float]:
    """An option's :data:`INPUTS` as the means over its runs (rows of a sweep's
    replications.csv, all of one scenario): lost = ``parts_missed`` + ``parts_scrapped``;
    good = ``parts_delivered`` (less ``spacing_outside_tol`` under ``quality.rule: spacing``);
    hours = ``sim_end_s`` / 3600; down_h = ``robot_down_fraction`` × hours; repairs =
    ``robot_failures``; maintenance 0 (a run's summary does not count its planned stops);
    ``energy_kwh`` where the runs have it, else 0."""
    from cell.sim.run_cost import options_per_h

    hours = runs["sim_end_s"] / 3600.0
    good = runs["parts_delivered"] - (runs["spacing_outside_tol"]
                                      if scenario.quality.rule == "spacing" else 0)
    energy = runs["energy_kwh"] if "energy_kwh" in runs else pd.Series(0.0, index=runs.index)
    return {"lost": float((runs["parts_missed"] + runs["parts_scrapped"]).mean()),
            "good": float(good.mean()), "hours": float(hours.mean()),
            "down_h": float((runs["robot_down_fraction"] * hours).mean()),
            "repairs": float(runs["robot_failures"].mean()), "maintenance": 0.0,
            "energy_kwh": float(energy.mean()), "options_per_h": options_per_h(scenario)}


def priced(rows: pd.DataFrame, costs: Any) -> pd.DataFrame:
    """``rows`` with each option's cost over its stretch, per good part and per hour."""
    missing = [c for c in INPUTS if c not in rows]
    if missing:
        raise ValueError(f"an option's row needs {', '.join(missing)}")
    from cell.sim.run_cost import cost as cost_of

    cost = cost_of(costs, rows["lost"], rows["energy_kwh"], rows["down_h"], rows["repairs"],
                   rows["maintenance"], rows["options_per_h"], rows["hours"])
    good, hours = rows["good"].astype(float), rows["hours"].astype(float)
    return rows.assign(cost=cost, cost_per_good_part=(cost / good).where(good > 0, math.nan),
                       cost_per_h=(cost / hours).where(hours > 0, math.nan))


def cheapest(table: pd.DataFrame, target: float) -> pd.Series | None:
    """The option (a row of :func:`priced`) losing at most ``target`` with the lowest cost per
    good part (ties: the first listed); None when no option meets the target."""
    meets = table[(table["lost"] <= target) & table["cost_per_good_part"].notna()]
    if meets.empty:
        return None
    return meets.iloc[int(np.argmin(meets["cost_per_good_part"].to_numpy()))]


def sentences(table: pd.DataFrame, targets: Sequence[float], name: str, unit: str) -> list[str]:
    """For the loss targets (``math.inf``: none), the cheapest option meeting each and what the
    next cheapest that meets it costs more, one sentence for targets with the same answer;
    ``name``: the column naming an option; ``unit``: what the losses are counted over
    ("per 500 parts", "a year")."""
    groups: list[tuple[list[float], Any, Any]] = []
    for target in targets:
        best = cheapest(table, target)
        runner = None
        if best is not None:
            runner = cheapest(table[table.index != best.name], target)
        key = (None if best is None else best.name, None if runner is None else runner.name)
        if groups and (None if groups[-1][1] is None else groups[-1][1].name,
                       None if groups[-1][2] is None else groups[-1][2].name) == key:
            groups[-1][0].append(target)
        else:
            groups.append(([target], best, runner))
    return [_sentence(ts, best, runner, table, name, unit) for ts, best, runner in groups]


def _goal(targets: list[float], unit: str) -> str:
    finite = [f"{t:,g}" for t in targets if math.isfinite(t)]
    text = ""
    if finite:
        listed = finite[0] if len(finite) == 1 else ", ".join(finite[:-1]) + " or " + finite[-1]
        text = f"At most {listed} part{'' if finite == ['1'] else 's'} lost {unit}"
    if len(finite) < len(targets):
        text = text + ", and with no loss target" if text else "With no loss target"
    return text


def _sentence(targets: list[float], best: Any, runner: Any, table: pd.DataFrame, name: str,
              unit: str) -> str:
    goal = _goal(targets, unit)
    if best is None:
        fewest = table.iloc[int(np.argmin(table["lost"].to_numpy()))]
        return f"{goal}: no option tried meets it (the fewest, {fewest['lost']:,.1f}, with {fewest[name]})."
    after = "; no other option meets it"
    if runner is not None:
        more = runner["cost_per_good_part"] - best["cost_per_good_part"]
        after = (f"; the next cheapest that meets it, {runner[name]}, costs " +
                 (f"{more:.4f} more a good part" if round(more, 4) > 0 else "as much to 4 decimals"))
    return (f"{goal}: cheapest with {best[name]}, {best['cost_per_good_part']:.4f} a good part "
            f"({best['lost']:,.1f} lost, {best['cost_per_h']:.2f} an hour){after}.")


def shares(row: pd.Series, costs: Any) -> dict[str, float]:
    """What an option's cost is made of, each term's share of it."""
    from cell.sim.run_cost import cost as cost_of

    def only(*keys: str) -> float:
        given = {k: row[k] if k in keys else 0.0 for k in TERMS}
        return float(cost_of(costs, **given, hours=row["hours"]))

    terms = {"lost parts": only("lost"), "energy": only("energy_kwh"), "downtime": only("down_h"),
             "repairs and maintenance": only("repairs", "maintenance"),
             "options": only("options_per_h")}
    total = sum(terms.values())
    return {k: v / total if total > 0 else math.nan for k, v in terms.items()}
