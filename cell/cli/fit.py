"""``cell fit TRACE.csv [--column interarrival_s] [--times] [--out SCENARIO.yaml]``: input modelling.

Fits candidate scipy.stats distributions to observed inter-arrival times by maximum
likelihood (:mod:`cell.experiments.fit.mle`), each within a time budget, prints them ranked with
their means and sds beside the data's, and writes the ``arrivals:`` block of the best one a
scenario accepts (each candidate is validated as a scenario holding it:
:mod:`cell.experiments.fit.scenario_check`; of those, when the best misses the data's mean or sd, the one
nearest them: :func:`~cell.experiments.fit.choice.choose`), with a histogram of the data and the
fitted densities.  A fit that does not stand for the data
(:func:`~cell.experiments.fit.choice.caution`) is said in a warning and in the block, which then
points to replaying the data as a trace.  ``--times`` reads the column as arrival times and
fits the gaps between them; gaps far out of the body of the data are flagged, and
``--max-gap S`` or ``--drop-outliers`` leaves them out.  ``--as time_to_failure`` (or
``time_to_repair``) fits times to failure or repair instead, right-censored where
``--censored COLUMN`` says so (:mod:`cell.experiments.fit.censored`), and writes that block of
the ``failures:`` section.  A log of arrivals is first tested for a trend, a rate that changes
with the time of day and correlated gaps (:mod:`cell.experiments.fit.pattern`); when the rate
changes, the block written is the rate profile the counts estimate with the base distribution
fitted to the gaps in operational time (``--iid``: one iid fit, the tests' result beside it).
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from cell.cli.fit_options import families_option, pattern_options
from cell.cli.fit_write import write
from cell.experiments.fit.block import FitOptions, fitted_block
from cell.experiments.fit.fitted_data import in_operational_time, read_data
from cell.experiments.fit.scenario_check import BLOCKS
from cell.plumbing.errors import ScenarioError

HELP = "fit a distribution to observed inter-arrival times (or times to failure or repair); write its block"
DESCRIPTION = ("Fit scipy.stats distributions to observed inter-arrival times by maximum likelihood, "
               "each within a time budget (--budget), rank them with their means and sds beside the "
               "data's, and write the arrivals: block of the best one a scenario accepts (or, if it "
               "misses the data's mean or sd, the one nearest them), with a histogram of the data under "
               "the fitted densities. When the written fit's mean or sd is more than 10 % off the data's, "
               "or the KS test rejects it (p < 0.001), a warning and a CAUTION comment in "
               "the block say so, with the line that replays the data themselves as a trace "
               "(arrivals.trace_csv). Gaps far out of the body of the data (beyond Q3 + 3 IQR: a line's "
               "stoppages) are flagged; --max-gap S or --drop-outliers leaves them out. Zero gaps (two "
               "parts logged in the same second) are refused, counted: no continuous distribution fits "
               "them, and leaving them out would lengthen the mean; log the times more finely, or replay "
               "the gaps as a trace (arrivals.trace_csv takes zeros). With --as time_to_failure or "
               "time_to_repair the column holds such times, right-censored where --censored COLUMN says "
               "1, true or yes, and the block written is that one of the failures: section. A log of "
               "arrivals (not with --as or --gaps) is tested for a trend (Laplace), counts by hour of a "
               "period (chi-square; --period-h, --period-start, or inferred) and correlated successive "
               "gaps (lag-1), each by permutation, Holm-corrected: an iid log is said to have a pattern "
               "at most 5 % of the time. When the rate changes with the hour, the arrivals: block holds "
               "the estimated profile and the distribution of the gaps in operational time; --iid "
               "writes one iid fit instead, with the tests' result beside it.")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("trace", help="CSV file of observed inter-arrival times (or times to failure "
                                      "or repair, with --as)")
    parser.add_argument("--column", default="interarrival_s", help="column to fit (default: %(default)s)")
    kind = parser.add_mutually_exclusive_group()
    kind.add_argument("--times", action="store_true",
                      help="the column holds arrival times (increasing seconds, or ISO date-times): "
                           "fit the gaps between them")
    kind.add_argument("--gaps", action="store_true",
                      help="the column holds gaps even though it never decreases (sorted gaps)")
    parser.add_argument("--out", default=None, metavar="SCENARIO.yaml",
                        help="write the block here (default: print it)")
    parser.add_argument("--figure", default=None, metavar="FILE.png",
                        help="histogram with the fitted densities (default: beside --out, as .png)")
    parser.add_argument("--families", default=None, metavar="A,B,...",
                        help="scipy.stats families to try (default: weibull_min, gamma, lognorm, "
                             "expon, norm; with --as: weibull_min, gamma, lognorm, expon)")
    parser.add_argument("--rank-by", choices=("aic", "ks"), default="aic",
                        help="rank by AIC or by the Kolmogorov-Smirnov D (default: %(default)s)")
    far = parser.add_mutually_exclusive_group()
    far.add_argument("--max-gap", type=float, default=None, metavar="S",
                     help="leave out gaps longer than S seconds (stoppages); the block says so")
    far.add_argument("--drop-outliers", action="store_true",
                     help="leave out the gaps beyond Q3 + 3 IQR (far out of the body of the data)")
    parser.add_argument("--budget", type=float, default=None, metavar="S",
                        help="seconds each family's fit may take (default 20): one that takes longer "
                             "is left out, with a line saying so")
    parser.add_argument("--as", dest="block", choices=BLOCKS, default="arrivals",
                        help="the block to write: arrivals (default), or time_to_failure or "
                             "time_to_repair of the failures: section (times, not gaps)")
    parser.add_argument("--period-h", type=float, default=None, metavar="H",
                        help="test the counts by hour of a period of H hours (8: a shift, 24: a "
                             "day; default: each of 8 and 24 the log spans twice)")
    parser.add_argument("--period-start", default=None, metavar="HH:MM",
                        help="where a period starts on the log's clock (default: the whole hour "
                             "the log begins in)")
    parser.add_argument("--iid", action="store_true",
                        help="write one iid fit even when the rate changes over the period (the "
                             "tests' results beside it)")
    parser.add_argument("--censored", default=None, metavar="COLUMN",
                        help="with --as: the column saying which times are right-censored (1, true "
                             "or yes: still working then; 0, false or no: failed, or repaired, then)")


def _destination(path: str | Path, option: str, taken: Sequence[Path]) -> Path:
    """An output file that can be written and overwrites neither the trace nor the other output."""
    from cell.plumbing.output.atomic import check_file

    p = Path(path)
    why = ("its directory does not exist" if str(path) and not p.parent.is_dir() else
           "would overwrite the trace or the other output" if str(path) and
           p.resolve() in {t.resolve() for t in taken} else "")
    if why:
        raise ScenarioError(p, option, str(p), why)
    check_file(path, option)  # refuses '-' too: no command writes to standard output
    return p


def _outputs(args: argparse.Namespace, trace: Path) -> tuple[Path | None, Path | None]:
    """--out and the figure (--figure, or beside --out as .png), each checked before any work."""
    out = _destination(args.out, "--out", [trace]) if args.out is not None else None
    if args.figure is not None and Path(args.figure).suffix.lower() != ".png":
        raise ScenarioError("--figure", "--figure", args.figure, "the figure is a PNG: name a .png file")
    if args.figure is None and out is not None and out.suffix.lower() == ".png":
        raise ScenarioError(out, "--out", str(out), "the figure goes beside --out as .png, onto --out "
                            "itself: name --out .yaml, or the figure with --figure")
    figure_arg = args.figure if args.figure is not None else out.with_suffix(".png") if out else None
    figure = _destination(figure_arg, "--figure", [trace, *([out] if out else [])]) \
        if figure_arg is not None else None
    return out, figure


def _replay(trace: Path, out: Path | None, column: str, times: bool) -> str:
    """How to replay the data themselves: the trace as it is, named from --out's directory,
    when its column is a run's (``interarrival_s``, gaps)."""
    if column != "interarrival_s" or times:
        return "arrivals.trace_csv (a CSV of the gaps in a column named interarrival_s)"
    path = os.path.relpath(trace.resolve(), out.resolve().parent) if out is not None else str(trace)
    return f"arrivals: {{trace_csv: {path}}}"


def main(args: argparse.Namespace) -> int:
    """Fit, print the table, write (or print) the block and the figure."""
    trace = Path(args.trace)
    out, figure = _outputs(args, trace)
    lifetimes = args.block != "arrivals"
    families = families_option(args, lifetimes)
    start_h = pattern_options(args, lifetimes)
    data = read_data(trace, args.column, lifetimes=lifetimes, times=args.times, gaps=args.gaps,
                     censored_by=args.censored, max_gap=args.max_gap,
                     drop_outliers=args.drop_outliers)
    replay = "" if lifetimes else _replay(trace, out, args.column, args.times)
    pattern = None
    if data.ordered is not None:
        from cell.experiments.fit.pattern import find_pattern

        pattern = find_pattern(data.ordered, data.first_h, args.period_h, start_h, data.kept)
        profile = pattern.profile()
        if pattern.by_time and not args.iid and profile is not None:
            data = in_operational_time(data, profile)
    options = FitOptions(args.block, args.column, args.rank_by, args.budget, bool(args.iid))
    result = fitted_block(options, trace, out, data, families, replay, pattern)
    write(args, data, result, out, figure)
    if data.flag:
        print(f"cell: warning: {data.flag}", file=sys.stderr)
    if result.warning:
        print(f"cell: warning: {result.warning}", file=sys.stderr)
    return 0
