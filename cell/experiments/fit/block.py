"""``cell fit``'s block: fit what was read, pick the fit to write (each candidate validated as a
scenario: :mod:`cell.experiments.fit.scenario_check`), and make its block and the table of
fits (:func:`fitted_block`); ``cell fit`` (:mod:`cell.cli.fit`) writes and prints them."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

from cell.experiments.fit.fitted_data import Data
from cell.experiments.fit.scenario_check import scenario_refuses
from cell.plumbing.errors import ScenarioError

if TYPE_CHECKING:
    from cell.experiments.fit.mle import Fit
    from cell.experiments.fit.pattern import Pattern

#: Where a time to failure or repair goes.
EQUIPMENT = "robot, input_belt, output_belt or sensor"


class FitOptions(NamedTuple):
    """What ``cell fit`` was asked: the block (``arrivals``, ``time_to_failure`` or
    ``time_to_repair``), the trace's column, the ranking, the time budget a family (None: the
    default) and whether to fit one iid distribution whatever the pattern tests found."""

    key: str
    column: str
    rank_by: str
    budget_s: float | None = None
    iid: bool = False


class Result(NamedTuple):
    """The fits, the one written and why (or ""), the warning (or ""), the block and the table."""

    fits: list[Fit]
    chosen: Fit
    warning: str
    block: str
    table: str


def _fits(options: FitOptions, trace: Path, data: Data, families: list[str]) -> list[Fit]:
    from cell.experiments.fit.budget import DEFAULT_BUDGET_S
    from cell.experiments.fit.censored import fit_lifetimes
    from cell.experiments.fit.mle import fit_trace

    budget = options.budget_s if options.budget_s is not None else DEFAULT_BUDGET_S
    try:
        if options.key == "arrivals":
            return fit_trace(data.values, families, rank_by=options.rank_by, budget_s=budget)
        return fit_lifetimes(data.values, data.censored, families, rank_by=options.rank_by, budget_s=budget)
    except ValueError as exc:
        raise ScenarioError(trace, options.column, data.what, str(exc)) from None


def refusals(fits: list[Fit], key: str, file: object, extra: str = "") -> dict[int, str]:
    """Why a scenario would refuse each fit's block (by ``id``; "" where it accepts it): the
    quick checks first (:func:`~cell.experiments.fit.choice.unusable`), then the scenario's own
    validation of the block as it would be written (with ``extra``, its profile line)."""
    from cell.experiments.fit.choice import unusable
    from cell.experiments.fit.output import block_yaml
    from cell.scenario.arrivals import MAX_INTERARRIVAL_S

    most = MAX_INTERARRIVAL_S if key == "arrivals" else math.inf
    return {id(f): unusable(f, most) or scenario_refuses(block_yaml(f, key, str(file)) + extra, key,
                                                         file)
            for f in fits}


def _method(fit: Fit, data: Data) -> str:
    """The block's line on how the fit was made ("" for the usual: maximum likelihood and KS)."""
    if data.censored is None:
        return ""
    return (f"maximum likelihood with right-censored times (scipy.stats.CensoredData), loc held at 0; "
            f"D = {fit.statistic:.4g} from the Kaplan-Meier estimate, AIC = {fit.aic:.1f}")


def _table(fits: list[Fit], data: Data, chosen: Fit, refused: dict[int, str], why: str) -> str:
    import numpy as np

    from cell.experiments.fit.output import DataMoments, format_table

    x = np.asarray(data.values, dtype=float)
    if data.censored is None:
        row = DataMoments(x.size, float(x.mean()), float(x.std(ddof=1)))
    else:
        row = DataMoments(x.size, math.nan, math.nan, f"n = {x.size}, {int(data.censored.sum())} censored")
    table = format_table(fits, row, lambda f: refused[id(f)] or ("written" if f is chosen else ""),
                         censored=data.censored is not None)
    if any(refused.values()):
        table += "\nA fit with a note other than 'written' is not written: a scenario would refuse it."
    return "\n".join([table, *data.notes, *([why] if why else [])])


def _pattern_said(pattern: Pattern | None, iid: bool) -> tuple[list[str], str]:
    """The lines on what the tests found (for the table and the block), and the caution when
    an iid fit is written for a log that is not iid ("" otherwise)."""
    if pattern is None:
        return [], ""
    lines = pattern.lines()
    if pattern.by_time and not iid:
        return lines + ["written: the rate profile the counts estimate (arrivals.profile) and "
                        "the distribution of the gaps in operational time; --iid writes one iid "
                        "fit instead"], ""
    if not pattern.found:
        return lines, ""
    found = ", ".join(f.name for f in pattern.findings if f.rejected)
    return lines, (f"the log is not iid ({found}): one iid fit does not stand for it"
                   + ("" if iid or pattern.by_time else "; a rate profile models a rate that "
                      "changes with the time of day, not a trend or correlated gaps"))


def fitted_block(options: FitOptions, trace: Path, out: Path | None, data: Data,
                 families: list[str], replay: str, pattern: Pattern | None = None) -> Result:
    """Fit, choose the fit to write, and make its block (with its caution and notes) and the
    table; ``replay`` is how to replay the data instead (for the caution; "" for none);
    ``pattern``: what the tests of the log found, and with a rate that changes over the
    period (and no ``--iid``) the profile written with the fit of the gaps in operational
    time (``data`` then holds those gaps)."""
    from cell.experiments.fit.choice import caution, choose, first_accepted
    from cell.experiments.fit.output import block_yaml
    from cell.experiments.fit.pattern import profile_yaml

    iid = options.iid
    profile = pattern.profile() if pattern is not None and pattern.by_time and not iid else None
    found, not_iid = _pattern_said(pattern, iid)
    fits = _fits(options, trace, data, families)
    key = options.key
    extra = profile_yaml(profile) if profile is not None else ""
    refused = refusals(fits, key, out if out is not None else "the printed block", extra)
    try:
        chosen, why = choose(fits, data.values, lambda f: refused[id(f)]) if data.censored is None \
            else first_accepted(fits, lambda f: refused[id(f)])
    except ValueError as exc:
        raise ScenarioError(trace, "--families", ",".join(families), str(exc)) from None
    warning = caution(chosen, data.values) if data.censored is None else ""
    warning = "; ".join(w for w in (warning, not_iid) if w)
    if warning and replay:
        warning += f". To run the data themselves, replay them: {replay}"
    notes = list(data.notes)
    if key != "arrivals":
        notes.append(f"put it under failures.EQUIPMENT ({EQUIPMENT}), with its "
                     f"{'time_to_repair' if key == 'time_to_failure' else 'time_to_failure'}")
    source = f"{trace}, column {options.column} ({data.what})"
    block = block_yaml(chosen, key, source, caution=warning, notes=[*found, *notes],
                       method=_method(chosen, data)) + extra
    table = "\n".join([_table(fits, data, chosen, refused, why), *found])
    return Result(fits, chosen, warning, block, table)
