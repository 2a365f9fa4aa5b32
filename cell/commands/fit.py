"""``cell fit TRACE.csv [--column interarrival_s] [--out SCENARIO.yaml]``: input modelling.

Fits candidate scipy.stats distributions to observed inter-arrival times by
maximum likelihood (:mod:`cell.analysis.fit`), prints them ranked, and writes
the ``arrivals:`` block of the best one that never gives a negative time,
with a histogram of the data and the fitted densities.
"""

from __future__ import annotations

import argparse
import os
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

from cell.errors import ScenarioError

HELP = "fit a distribution to observed inter-arrival times; write the arrivals block"
DESCRIPTION = __doc__.splitlines()[2] if __doc__ else ""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("trace", help="CSV file of observed inter-arrival times")
    parser.add_argument("--column", default="interarrival_s", help="column to fit (default: %(default)s)")
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
    p = Path(path)
    why = ("its directory does not exist" if not p.parent.is_dir() else
           "is a directory; give a file name" if p.is_dir() else
           "would overwrite the trace or the other output" if p.resolve() in {t.resolve() for t in taken}
           else "")
    if why:
        raise ScenarioError(p, option, str(p), why)
    return p


def main(args: argparse.Namespace) -> int:
    """Fit, print the table, write (or print) the arrivals block and the figure."""
    from scipy import stats

    from cell.analysis.fit import (
        DEFAULT_FAMILIES,
        arrivals_yaml,
        draw,
        fit_trace,
        format_table,
        read_column,
    )

    trace = Path(args.trace)
    out = _destination(args.out, "--out", [trace]) if args.out else None
    figure_arg = args.figure or (out.with_suffix(".png") if out else None)
    figure = _destination(figure_arg, "--figure", [trace, *([out] if out else [])]) if figure_arg else None
    chosen_families = args.families if args.families is not None else ",".join(DEFAULT_FAMILIES)
    families = [f.strip() for f in str(chosen_families).split(",") if f.strip()]
    for family in families or [""]:
        if not isinstance(getattr(stats, family, None), stats.rv_continuous):
            raise ScenarioError("--families", "--families", family,
                                "not a continuous distribution in scipy.stats")
    values = read_column(trace, args.column)
    try:
        fits = fit_trace(values, families, rank_by=getattr(args, "rank_by", "aic"))
    except ValueError as exc:
        raise ScenarioError(trace, args.column, f"{values.size} values", str(exc)) from None
    usable = [f for f in fits if f.nonnegative]
    if not usable:
        raise ScenarioError(trace, "--families", ",".join(families),
                            "no fitted family keeps inter-arrival times non-negative")
    chosen = usable[0]
    block = arrivals_yaml(chosen, f"{trace}, column {args.column} ({values.size} values)")
    table = format_table(fits)
    if chosen is not fits[0]:
        table += f"\nChosen: {chosen.family}, the best fit that allows no negative times."
    jobs: list[tuple[Path | None, str, Callable[[Path], object]]] = [
        (figure, "--figure", lambda tmp: draw(values, fits, tmp, best=chosen, xlabel=args.column)),
        (out, "--out", lambda tmp: tmp.write_text(block, encoding="utf-8"))]
    staged: list[tuple[Path, Path]] = []
    try:  # every file staged beside its destination first, then all moved into place
        for dest, option, write in jobs:
            if dest is None:
                continue
            try:
                fd, name = tempfile.mkstemp(dir=dest.parent, prefix=f".{dest.name}.", suffix=".tmp")
                os.close(fd)
                staged.append((Path(name), dest))
                write(Path(name))
            except OSError as exc:
                raise ScenarioError(dest, option, str(dest), f"cannot write: {exc.strerror or exc}") from None
        for tmp, dest in staged:
            os.replace(tmp, dest)
    finally:
        for tmp, _ in staged:
            tmp.unlink(missing_ok=True)
    comment = "# " if out is None else ""  # printed table and block together are valid YAML
    print("\n".join(comment + line for line in table.splitlines()))
    print(block.rstrip("\n") if out is None else f"wrote {out}")
    if figure is not None:
        print(f"{comment}wrote {figure}")
    return 0
