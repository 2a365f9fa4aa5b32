"""``cell fit``'s options checked before any work: the families to try and the options that go
with ``--as`` or not (:func:`families_option`), and the pattern tests' (:func:`pattern_options`)."""

from __future__ import annotations

import argparse
import math

from cell.plumbing.errors import ScenarioError


def seconds_option(value: float | None, option: str) -> None:
    """Refuse an option's number of seconds unless it is finite and above 0 (None: not given)."""
    if value is not None and not (math.isfinite(value) and value > 0.0):
        raise ScenarioError(option, option, value, "must be a number of seconds > 0")


def families_option(args: argparse.Namespace, lifetimes: bool) -> list[str]:
    """The families to try (--families, or the defaults for the block), each checked; and the
    options that go with --as, or not."""
    from cell.experiments.fit.censored import LIFETIME_FAMILIES
    from cell.experiments.fit.mle import DEFAULT_FAMILIES, family_of

    seconds_option(args.max_gap, "--max-gap")
    seconds_option(args.budget, "--budget")
    if args.censored is not None and not lifetimes:
        raise ScenarioError("--censored", "--censored", args.censored,
                            "censored times are times to failure or repair: give --as time_to_failure "
                            "or --as time_to_repair")
    if lifetimes and (args.max_gap is not None or args.drop_outliers):
        option = "--max-gap" if args.max_gap is not None else "--drop-outliers"
        raise ScenarioError(option, option, args.max_gap if args.max_gap is not None else True,
                            "leaves out gaps between arrivals, not times to failure or repair")
    if args.censored is not None and args.times:
        raise ScenarioError("--censored", "--censored", args.censored,
                            "with --times the times are differences of a log: none is censored")
    default = LIFETIME_FAMILIES if lifetimes else DEFAULT_FAMILIES
    chosen = args.families if args.families is not None else ",".join(default)
    families = [f.strip() for f in str(chosen).split(",") if f.strip()]
    for family in families or [""]:
        try:
            family_of(family)
        except ValueError:
            raise ScenarioError("--families", "--families", family,
                                "not a continuous distribution in scipy.stats") from None
    return families


def pattern_options(args: argparse.Namespace, lifetimes: bool) -> float | None:
    """--period-h, --period-start (as hours) and --iid checked: a period of hours within a
    scenario's bounds, a start HH:MM within the day, none with --as or --gaps (no log order)."""
    from cell.scenario.sections import MAX_HOURS

    given = [(o, v) for o, v in (("--period-h", args.period_h), ("--period-start", args.period_start),
                                 ("--iid", args.iid or None)) if v is not None]
    if given and (lifetimes or args.gaps):
        option, value = given[0]
        raise ScenarioError(option, option, value, "tests a log of arrivals in its order: not with "
                            + ("--as" if lifetimes else "--gaps (sorted gaps have no order)"))
    if args.period_h is not None and not (math.isfinite(args.period_h) and 0 < args.period_h <= MAX_HOURS):
        raise ScenarioError("--period-h", "--period-h", args.period_h,
                            f"must be a number of hours > 0, at most {MAX_HOURS:g}")
    if args.period_start is None:
        return None
    text = str(args.period_start)
    hh, sep, mm = text.partition(":")
    if not (sep and hh.isdigit() and mm.isdigit() and len(mm) == 2 and int(hh) < 24 and int(mm) < 60):
        raise ScenarioError("--period-start", "--period-start", text, "must be a clock time HH:MM, "
                            "00:00 to 23:59")
    return int(hh) + int(mm) / 60.0
