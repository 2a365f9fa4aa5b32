"""``cell compare A B [--replications N] [--seed S] [--workers N] [--out DIR]``.

Two scenarios (files or built-in names) run side by side with common random
numbers: replication r of both draws the same parts, so their difference is
taken replication by replication (a paired t interval).  Prints, per headline
measure, which is better, by how much, and whether the interval excludes zero;
``--out DIR`` writes the report (as ``cell sweep --report``) and the
replications, as a unit.  Counts (parts delivered, lost, ...) and extremes (closest
spacing, fastest belt, ...) are per run, after the warm-up: if A and B differ in
``run.parts`` or ``run.warmup_parts``, or either has ``run.warmup_parts: auto`` (MSER-5
cuts each run where its own output settles), a warning says so, the verdict leaves them
uncompared and ``differences.csv`` leaves them out (:mod:`cell.experiments.sweep.windows`);
rates still compare.
"""

from __future__ import annotations

import argparse
import math
from typing import TYPE_CHECKING

from cell.cli.common import check_workers, set_argument, workers_argument
from cell.reporting.compare_verdict import PRACTICAL_PER_1000

if TYPE_CHECKING:
    import pandas as pd

    from cell.experiments.sweep import Sweep
    from cell.experiments.sweep.spec import Point
    from cell.reporting.compare_verdict import Judged, Verdict
    from cell.reporting.formatting import Headline
    from cell.scenario.run_length import RunLength
    from cell.scenario.schema import Scenario

HELP = "compare two scenarios, paired over common random numbers"
DESCRIPTION = ("Run scenarios A and B with the same replications (common random numbers) and "
               "say, per headline measure, which is better, by how much (paired confidence "
               "interval of A - B) and whether the interval excludes zero.  The verdict, "
               "report.md and the CSVs' scenario column label A and B by each scenario's "
               "name setting (a file without one: its file name); if the two are the same, "
               "by their file names; if those are the same too, as 'A: <name>' and "
               "'B: <name>'.  The overall verdict weighs each difference shown in parts per "
               "1,000: the largest at or above --practical decides; smaller ones are trivial.")
DEFAULT_REPLICATIONS = 100


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("a", metavar="A", help="a scenario file, or a built-in name (baseline)")
    p.add_argument("b", metavar="B", help="the scenario to compare A with")
    p.add_argument("--replications", type=int, default=DEFAULT_REPLICATIONS,
                   help=f"replications of each (default {DEFAULT_REPLICATIONS})")
    p.add_argument("--seed", type=int, default=None,
                   help="root seed of the replications' streams (default: A's run.seed)")
    workers_argument(p)
    p.add_argument("--out", default=None, metavar="DIR",
                   help="write report.md, summary.csv, differences.csv, figures and "
                        "replications.csv into DIR")
    set_argument(p)
    p.add_argument("--policy", default=None, metavar="NAME",
                   help="run this policy on both sides (controller.policy of A and B)")
    p.add_argument("--practical", type=float, default=PRACTICAL_PER_1000, metavar="PER_1000",
                   help="the smallest difference that decides the overall verdict, in parts per "
                        f"1,000 (default {PRACTICAL_PER_1000:g}); a smaller one shown by its "
                        "interval is said, and called trivial")


def _stem(arg: str) -> str:
    """A scenario argument's file name without ``.yaml`` (a built-in's name as given)."""
    from pathlib import Path

    return Path(arg).stem if arg.endswith((".yaml", ".yml")) else Path(arg).name


def labels(a: Scenario, b: Scenario, arg_a: str, arg_b: str) -> tuple[str, str]:
    """What A and B are called (``DESCRIPTION``): their ``name:``, else their file
    names, else ``A: ...`` and ``B: ...``: the first pair that tells them apart."""
    for la, lb in ((a.name, b.name), (_stem(arg_a), _stem(arg_b))):
        if la != lb:
            return la, lb
    return f"A: {a.name}", f"B: {b.name}"


def _suggest(va: object, vb: object) -> str:
    """A value valid for both (``--set`` sets it for both): the larger number, the fixed
    warm-up when the other is ``auto``, or ``N`` (said to be a fixed number) when both are
    ``auto``: no number is known before the runs, MSER-5 choosing one per run."""
    numbers = [v for v in (va, vb) if isinstance(v, int)]
    return str(max(numbers)) if numbers else "N"


def _sides(sweep: Sweep) -> tuple[tuple[str, Point], tuple[str, Point]]:
    """(label, point) of A and of B."""
    (la, a), (lb, b) = ((dict(p.values)["scenario"], p) for p in sweep.points)
    return (la, a), (lb, b)


def window_warning(sweep: Sweep) -> str | None:
    """One line if A's and B's counts and extremes are over different windows, else None."""
    from cell.experiments.sweep.windows import AUTO, AUTO_WHY, WINDOW_MEASURES_TEXT, windows_apart

    (la, a), (lb, b) = _sides(sweep)
    differ = windows_apart(a.scenario, b.scenario)
    if not differ:
        return None
    said = {"parts": "runs {} parts", "length": "runs {}", "warmup_parts": "has run.warmup_parts {}"}
    what = "; ".join(f"{la} {said[k].format(va)}, {lb} {vb}" for k, va, vb in differ)
    if any(AUTO in (va, vb) for _, va, vb in differ):
        what += f" (auto: {AUTO_WHY}, so {la}'s and {lb}'s windows differ in length)"
    sets = " ".join("--set run.hours=H" if k == "length" else  # H hours for both
                    f"--set run.{k}={_suggest(va, vb)}" for k, va, vb in differ)
    if any(va == vb == AUTO for _, va, vb in differ):
        sets += ", N a fixed number of parts"
    if any(k == "length" for k, _, _ in differ):
        sets += ", H the hours of both"
    return (f"{what}: {WINDOW_MEASURES_TEXT} are not comparable; compare the rates, or give "
            f"both the same window ({sets})")


def nominal_warning(sweep: Sweep) -> str | None:
    """One line if A's or B's controller aims at a nominal cycle it states that is off its
    arrivals' mean (as ``cell run`` warns of a run), else None."""
    from cell.reporting.run_summary import NOMINAL_MISMATCH, nominal_mismatch, nominal_off

    said: dict[str, list[str]] = {}
    for label, p in _sides(sweep):
        if abs(p.nominal_gap) > NOMINAL_MISMATCH:  # NaN: it follows the arrivals
            cycle = float(p.scenario.controller.nominal_cycle_s or math.nan)
            said.setdefault(nominal_mismatch(cycle, cycle / (1 + p.nominal_gap)), []).append(label)
    if not said:
        return None
    return nominal_off("; ".join(f"{' and '.join(who)}: {text}" for text, who in said.items()),
                       " (--set controller.nominal_cycle_s=null)")


def main(args: argparse.Namespace) -> int:
    import sys
    import tempfile
    from pathlib import Path

    from cell.experiments.sweep import run_sweep, simulate_summary
    from cell.experiments.sweep.spec import MAX_RUNS, comparison
    from cell.plumbing.errors import CellError
    from cell.plumbing.output.paths import check_umask
    from cell.scenario.overrides import parse_sets
    from cell.scenario.schema import load_scenario

    check_umask("cell compare's temporary folder")  # the runs go there, --out or not
    sets = parse_sets(args.sets)
    if args.policy is not None:
        sets["controller.policy"] = args.policy
    a, b = load_scenario(args.a, sets), load_scenario(args.b, sets)
    if args.replications < 2:
        raise CellError(f"--replications {args.replications}: must be at least 2 "
                        "(a confidence interval needs two)")
    if 2 * args.replications > MAX_RUNS:
        raise CellError(f"--replications {args.replications:,}: at most {MAX_RUNS // 2:,} "
                        f"(two scenarios: {MAX_RUNS:,} runs, a sweep's limit)")
    if args.seed is not None and not 0 <= args.seed < 2**63:
        raise CellError(f"--seed {args.seed}: must be a whole number from 0 to 2**63 - 1")
    if not (math.isfinite(args.practical) and args.practical >= 0):
        raise CellError(f"--practical {args.practical}: must be a number of parts per 1,000, "
                        "0 or more")
    check_workers(args.workers)
    seed = a.run.seed if args.seed is None else args.seed
    sweep = comparison(a, b, labels(a, b, args.a, args.b), args.replications, seed)
    target = None
    if args.out:
        from cell.plumbing.output.atomic import OutputDir
        from cell.reporting.experiment import REPORT_FILES, Target

        names = (*REPORT_FILES, "replications.csv")
        OutputDir.check(args.out, names)  # before anything runs
        target = Target(Path(args.out), names, False)
    if nominal := nominal_warning(sweep):
        print(f"cell: warning: {nominal}", file=sys.stderr)
    warning = window_warning(sweep)
    if warning:
        print(f"cell: warning: {warning}", file=sys.stderr)
    with tempfile.TemporaryDirectory(prefix="cell-compare-") as work:
        outcome = run_sweep(sweep, work, workers=args.workers, replicate=simulate_summary,
                            warn_windows=False)  # said above, in compare's words
        replications = outcome.replications
    from cell.reporting.experiment import difference_table, summary_table

    tables = summary_table(replications, sweep), difference_table(replications, sweep)
    print(verdict(*tables, sweep, replications, args.practical))
    if target is not None:
        from cell.reporting.experiment import write_report

        write_report(replications, sweep, target, command_line(args, seed), warning, tables)
        print(f"wrote {args.out}/: report.md, summary.csv, differences.csv, figures, "
              "replications.csv")
    return 0


def command_line(args: argparse.Namespace, seed: int) -> str:
    """The command that reproduces this comparison, quoted for a shell: its scenarios,
    replications, seed and every ``--set``."""
    import shlex

    words = ["cell", "compare", args.a, args.b, "--replications", str(args.replications),
             "--seed", str(seed)]
    for value in args.sets or ():
        words += ["--set", value]
    if args.practical != PRACTICAL_PER_1000:
        words += ["--practical", f"{args.practical:g}"]
    return shlex.join(words)


def verdict(summary: pd.DataFrame, differences: pd.DataFrame, sweep: Sweep,
            replications: pd.DataFrame | None = None,
            practical: float = PRACTICAL_PER_1000) -> str:
    """A few lines: per headline measure (and OEE), which is better, and A's difference from B
    (A - B) as a sentence with A its subject (``b better: a delivers 3.1 ± 0.4 parts fewer than
    b ...``), then the overall verdict (:func:`judgement`).  Counts and extremes are not
    compared if A and B take them over different windows (run length, warm-up)."""
    from cell.reporting.compare_verdict import overall_line

    lines, judged = judgement(summary, differences, sweep, replications, practical)
    return "\n".join([*lines, overall_line(judged)])


def judgement(summary: pd.DataFrame, differences: pd.DataFrame, sweep: Sweep,
              replications: pd.DataFrame | None = None,
              practical: float = PRACTICAL_PER_1000) -> tuple[list[str], Verdict]:
    """The verdict's lines but its last, and the overall verdict they lead to, weighed by
    practical size (:mod:`cell.reporting.compare_verdict`, ``practical`` parts per 1,000)."""
    from cell.cli.compare_rates import (
        RATE_FREE,
        SHOWN_ONLY,
        rate_error_s,
        rate_free,
        rates_differ,
        still_sides,
    )
    from cell.experiments.sweep.windows import setting, windows_apart
    from cell.reporting.compare_verdict import OEE, OEE_LOSSES, SCALES, Judged, decide, losses_line
    from cell.reporting.formatting import HEADLINES
    from cell.scenario.run_length import RunLength

    (la, a), (lb, b) = _sides(sweep)
    differ = windows_apart(a.scenario, b.scenario)
    errors = (rate_error_s(a.scenario.arrivals, a.scenario.base_dir),
              rate_error_s(b.scenario.arrivals, b.scenario.base_dir))
    demand = rates_differ(summary, la, lb, errors, sweep.confidence)
    length_a, length_b = RunLength.of(a.scenario.run), RunLength.of(b.scenario.run)
    length = length_a if length_a == length_b else None
    lines = [_verdict_header(sweep, la, a, lb, b, length_a, length_b)]
    if demand:
        lines.append(f"  {demand}")
    lines += [f"  {w}" for w in still_sides(summary, la, lb)]
    apart = ", ".join(f"{setting(k)} {va} against {vb}" for k, va, vb in differ)
    judged: list[Judged] = []
    measures = (*HEADLINES, OEE)
    width = max(len(t) for t in [*(h.title for h in measures), *(r[0] for r in RATE_FREE)])
    scales = {m: _both(summary, m, la, lb) for m in SCALES}
    if not scales["parts_arrived"] > 0 and length is not None and length.unit == "part":
        scales["parts_arrived"] = float(length.number)  # a summary without the column
    for h in measures:
        line = _headline_verdict(h, summary, differences, la, lb, length, width,
                                 apart if differ else None, bool(demand), judged, scales)
        if line is not None:
            lines.append(line)
    losses = losses_line(_pairs(summary, OEE_LOSSES, la, lb), la, lb, width)
    if losses is not None:
        lines.append(losses)
    if replications is not None:
        for title, side, size, line in rate_free(replications, sweep, la, lb, width):
            lines.append(line)
            if demand and title not in SHOWN_ONLY:
                judged.append(Judged(title, side, size))
    return lines, decide(judged, la, lb, practical, bool(demand))


def _pairs(summary: pd.DataFrame, measures: tuple[str, ...], la: str, lb: str
           ) -> dict[str, tuple[float, float]]:
    """Each measure's (A's mean, B's mean), for those both sides have."""
    out = {}
    for m in measures:
        rows = summary[summary["measure"] == m].set_index("scenario")["mean"]
        if {la, lb} <= set(rows.index):
            out[m] = (float(rows[la]), float(rows[lb]))
    return out


def _both(summary: pd.DataFrame, measure: str, la: str, lb: str) -> float:
    """A measure's mean over A's and B's means (NaN if either lacks it)."""
    rows = summary[summary["measure"] == measure].set_index("scenario")["mean"]
    return float((rows[la] + rows[lb]) / 2) if {la, lb} <= set(rows.index) else math.nan


def _verdict_header(sweep: Sweep, la: str, a: Point, lb: str, b: Point,
                    length_a: RunLength, length_b: RunLength) -> str:
    """The verdict's first line: the two sides, the replications, run lengths and seed."""
    level = f"{sweep.confidence * 100:g} %"
    of = (f" of {length_a}" if length_a == length_b else
          f" of {length_a.number} and {length_b}" if length_a.unit == length_b.unit else
          f" of {length_a} and {length_b}")
    return (f"{la} ({a.policy}) against {lb} ({b.policy}): {sweep.replications} replications"
            f"{of}, seed {sweep.seed}, common random numbers; A - B with its paired "
            f"{level} confidence interval")


def _headline_verdict(h: Headline, summary: pd.DataFrame, differences: pd.DataFrame, la: str,
                      lb: str, length: RunLength | None, width: int, apart: str | None,
                      demand: bool, weighed: list[Judged], scales: dict[str, float]) -> str | None:
    """One headline measure's verdict line (None if it was not measured); its side (1: A
    better, -1: B better, 0: neither) and size (parts per 1,000; ``scales``: the parts
    arrived and delivered, the means of both sides) are appended to ``weighed`` unless the
    arrival rates differ and the measure grows with the demand.  ``apart``: how the runs'
    windows differ, None if they do not."""
    from cell.experiments.sweep.windows import window_kind
    from cell.reporting.compare_verdict import Judged, per_1000
    from cell.reporting.formatting import better, number, too_few

    d = differences[differences["measure"] == h.column]
    windowed = window_kind(h.column)
    if windowed and apart is not None and h.column in set(summary["measure"]):
        return (f"  {h.title:<{width}}  not compared: {windowed}, over different "
                f"windows ({apart}); compare the rates")
    if d.empty:
        return None
    row = d.iloc[0]
    means = summary[summary["measure"] == h.column].set_index("scenario")["mean"]
    if int(row["n"]) < 2:
        return (f"  {h.title:<{width}}  not compared: "
                f"{too_few(int(row['n']), sides='both A and B')}")
    what, judged = _difference_said(h, row, la, lb, length)
    side = better(h, float(means[la]), float(means[lb])) if judged else 0
    who = {1: f"{la} better", -1: f"{lb} better", 0: "neither"}[side]
    if h.better == "one" and side:
        who += " (nearer 1 is better)"
    if demand and h.column in DEMAND_BOUND:
        who = "not judged (arrival rates differ)"
    else:
        weighed.append(Judged(h.title, side, per_1000(h.column, float(row["mean"]),
                                                      float(means[la]), float(means[lb]), scales)))
    shown = f"{number(float(means[la]))} against {number(float(means[lb]))}"
    return f"  {h.title:<{width}}  {who}: {what}; means {shown}"


def _difference_said(h: Headline, row: pd.Series, la: str, lb: str,
                     length: RunLength | None) -> tuple[str, bool]:
    """A - B for one measure as a sentence with A its subject, and whether it is judged (the
    paired interval excludes 0, or A and B differ by the same in every replication)."""
    from cell.reporting.formatting import half_width, number, plus_minus

    mean, sd, lo, hi = (float(row[k]) for k in ("mean", "sd", "ci_low", "ci_high"))
    if sd == 0.0:
        what = (f"{la} and {lb} equal in every replication" if mean == 0 else
                f"{h.says(la, number(abs(mean)), mean, lb, length)} in every replication")
        return what, bool(mean != 0)
    judged = not (lo <= 0.0 <= hi)
    what = (f"{h.says(la, plus_minus(abs(mean), half_width(row)), mean, lb, length)} "
            + ("(interval excludes 0)" if judged else
               "(interval includes 0: no difference shown)"))
    return what, judged


#: Measures that grow with the demand: with different arrival rates they say more parts
#: came, not which cell is better, and are left unjudged (the rate-free ones judge).
DEMAND_BOUND = frozenset({"parts_per_hr_wallclock", "parts_delivered", "parts_missed",
                          "spacing_outside_tol", "actual_cycle_wallclock_s", "oee"})
