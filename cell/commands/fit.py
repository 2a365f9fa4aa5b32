"""``cell fit TRACE.csv [--column interarrival_s] [--times] [--out SCENARIO.yaml]``: input modelling.

Fits candidate scipy.stats distributions to observed inter-arrival times by
maximum likelihood (:mod:`cell.analysis.fit`), prints them ranked, and writes
the ``arrivals:`` block of the best one that never gives a negative time (or, when
that one misses the data's mean or sd, the one nearest them: :func:`~cell.analysis.fit.choose`),
with a histogram of the data and the fitted densities.  A fit that does not stand for the
data (:func:`~cell.analysis.fit.caution`) is said in a warning and in the block, which
then points to replaying the data as a trace.  ``--times`` reads the column as arrival
times and fits the gaps between them.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from cell.errors import ScenarioError

HELP = "fit a distribution to observed inter-arrival times; write the arrivals block"
DESCRIPTION = ("Fit scipy.stats distributions to observed inter-arrival times by maximum likelihood, "
               "rank them, and write the arrivals: block of the best one that never gives a negative "
               "time (or, if it misses the data's mean or sd, the one nearest them), with a histogram "
               "of the data under the fitted densities. When the written fit's mean or sd is off the "
               "data's, or the Kolmogorov-Smirnov test rejects it (p < 0.001), a warning and a comment "
               "in the block say so, with the line that replays the data themselves as a trace "
               "(arrivals.trace_csv). Zero gaps (two parts "
               "logged in the same second) are refused, counted: no continuous distribution fits them, "
               "and leaving them out would lengthen the mean; log the times more finely, or replay the "
               "gaps as a trace (arrivals.trace_csv takes zeros).")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("trace", help="CSV file of observed inter-arrival times")
    parser.add_argument("--column", default="interarrival_s", help="column to fit (default: %(default)s)")
    kind = parser.add_mutually_exclusive_group()
    kind.add_argument("--times", action="store_true",
                      help="the column holds arrival times (increasing seconds, or ISO date-times): "
                           "fit the gaps between them")
    kind.add_argument("--gaps", action="store_true",
                      help="the column holds gaps even though it never decreases (sorted gaps)")
    parser.add_argument("--out", default=None, metavar="SCENARIO.yaml",
                        help="write the arrivals: block here (default: print it)")
    parser.add_argument("--figure", default=None, metavar="FILE.png",
                        help="histogram with the fitted densities (default: beside --out, as .png)")
    parser.add_argument("--families", default=None, metavar="A,B,...",
                        help="scipy.stats families to try (default: weibull_min, gamma, lognorm, "
                             "expon, norm)")
    parser.add_argument("--rank-by", choices=("aic", "ks"), default="aic",
                        help="rank by AIC or by the Kolmogorov-Smirnov D (default: %(default)s)")


def _destination(path: str | Path, option: str, taken: Sequence[Path]) -> Path:
    """An output file that can be written and overwrites neither the trace nor the other output."""
    from cell.output import check_file

    p = Path(path)
    why = ("its directory does not exist" if str(path) and not p.parent.is_dir() else
           "would overwrite the trace or the other output" if str(path) and
           p.resolve() in {t.resolve() for t in taken} else "")
    if why:
        raise ScenarioError(p, option, str(p), why)
    check_file(path, option)  # refuses '-' too: no command writes to standard output
    return p


def _replay(trace: Path, out: Path | None, column: str, times: bool) -> str:
    """How to replay the data themselves: the trace as it is, named from --out's directory,
    when its column is a run's (``interarrival_s``, gaps)."""
    if column != "interarrival_s" or times:
        return "arrivals.trace_csv (a CSV of the gaps in a column named interarrival_s)"
    path = os.path.relpath(trace.resolve(), out.resolve().parent) if out is not None else str(trace)
    return f"arrivals: {{trace_csv: {path}}}"


def main(args: argparse.Namespace) -> int:
    """Fit, print the table, write (or print) the arrivals block and the figure."""
    from cell.analysis.fit import (
        DEFAULT_FAMILIES,
        arrivals_yaml,
        caution,
        choose,
        draw,
        family_of,
        fit_trace,
        format_table,
    )
    from cell.analysis.fit_input import read_column

    trace = Path(args.trace)
    out = _destination(args.out, "--out", [trace]) if args.out is not None else None
    if args.figure is not None and Path(args.figure).suffix.lower() != ".png":
        raise ScenarioError("--figure", "--figure", args.figure, "the figure is a PNG: name a .png file")
    if args.figure is None and out is not None and out.suffix.lower() == ".png":
        raise ScenarioError(out, "--out", str(out), "the figure goes beside --out as .png, onto --out "
                            "itself: name --out .yaml, or the figure with --figure")
    figure_arg = args.figure if args.figure is not None else out.with_suffix(".png") if out else None
    figure = _destination(figure_arg, "--figure", [trace, *([out] if out else [])]) \
        if figure_arg is not None else None
    chosen_families = args.families if args.families is not None else ",".join(DEFAULT_FAMILIES)
    families = [f.strip() for f in str(chosen_families).split(",") if f.strip()]
    for family in families or [""]:
        try:
            family_of(family)
        except ValueError:
            raise ScenarioError("--families", "--families", family,
                                "not a continuous distribution in scipy.stats") from None
    times = args.times
    values = read_column(trace, args.column, times=times, sorted_ok=args.gaps)
    count = f"{values.size} gaps between {values.size + 1} arrival times" if times else \
        f"{values.size} values"
    try:
        fits = fit_trace(values, families, rank_by=args.rank_by)
    except ValueError as exc:
        raise ScenarioError(trace, args.column, count, str(exc)) from None
    try:
        chosen, why = choose(fits, values)
    except ValueError as exc:
        raise ScenarioError(trace, "--families", ",".join(families), str(exc)) from None
    warning = caution(chosen, values)
    if warning:
        warning += f". To run the data themselves, replay them: {_replay(trace, out, args.column, times)}"
    block = arrivals_yaml(chosen, f"{trace}, column {args.column} ({count})", warning)
    table = format_table(fits) + (f"\n{why}" if why else "")
    from cell.output import atomic_paths

    targets = [t for t in (figure, out) if t is not None]
    with atomic_paths(*targets) as tmps:  # both written in full, then put in place together
        staged = dict(zip(targets, tmps))
        if figure is not None:
            draw(values, fits, staged[figure], best=chosen,
                 xlabel=f"gaps between {args.column}" if times else args.column)
        if out is not None:
            staged[out].write_text(block, encoding="utf-8")
    comment = "# " if out is None else ""  # printed table and block together are valid YAML
    print("\n".join(comment + line for line in table.splitlines()))
    print(block.rstrip("\n") if out is None else f"wrote {out}")
    if figure is not None:
        print(f"{comment}wrote {figure}")
    if warning:
        print(f"cell: warning: {warning}", file=sys.stderr)
    return 0
