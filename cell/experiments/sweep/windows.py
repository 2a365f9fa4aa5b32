"""The windows a run's counts and extremes are taken over, and the paired comparisons
they spoil.

A run's summary is taken over its window: its ``run.parts`` (or the parts that come in
its ``run.hours``), after the ``run.warmup_parts`` of warm-up. Two kinds of measure
depend on the window's length, not only on how the cell behaves in it: its *counts*
(parts delivered, parts lost, spacings outside tolerance, belt limits: its whole-number
columns) and its *extremes* (the closest and widest spacing, the longest hold at the
feeder, the belts' slowest and fastest, the simulated end: a longer run sees a more
extreme value). So two points' counts and extremes compare only if both have the same
window; their rates and means (parts/hr, actual cycle, IP) compare whatever the windows.
``cell compare`` and ``cell sweep`` both warn when a paired comparison's points differ
there, and leave its counts and extremes out of ``differences.csv``
(:func:`window_measures` decides which they are, for both).
"""

from __future__ import annotations

from dataclasses import fields
from typing import TYPE_CHECKING, Any

from cell.experiments.sweep.options import distinct, show
from cell.sim.records import RunSummary

if TYPE_CHECKING:
    from cell.experiments.sweep.spec import Pair, Sweep
    from cell.scenario.schema import Scenario

#: The ``run`` settings that decide a run's window (``length``: its run.parts or run.hours,
#: where one of the two runs is given in hours).
WINDOW_KEYS = ("parts", "length", "warmup_parts")

#: The warm-up MSER-5 chooses run by run (``run.warmup_parts: auto``).
AUTO = "auto"

#: Why ``auto`` on either side puts two runs' counts over different windows.
AUTO_WHY = "MSER-5 cuts each run's warm-up where its own output settles"

#: The words of a summary column's name that make it an extreme over the window.
EXTREME_WORDS = frozenset({"min", "max"})

#: The simulated end: the run's latest instant, an extreme of its own.
END = "sim_end_s"

#: The window-dependent measures in words, as the warnings name them.
WINDOW_MEASURES_TEXT = ("counts and extremes (parts delivered, parts lost, spacings outside "
                        "tolerance, closest and widest spacing, the belts' slowest and "
                        "fastest, ...)")


def count_measures() -> list[str]:
    """The count columns of a run's summary: its whole-number measures but the warm-up's
    own length (``warmup_parts``, the window, not a count over it), in order."""
    return [f.name for f in fields(RunSummary) if isinstance(f.default, int)
            and not isinstance(f.default, bool) and f.name != "warmup_parts"]


def extreme_measures() -> list[str]:
    """The extreme columns of a run's summary: a minimum or a maximum over the window
    (``spacing_min_in``, ``feed_delay_max_s``, ``input_speed_max_in_s``, ...) and the
    simulated end, in order."""
    return [f.name for f in fields(RunSummary)
            if EXTREME_WORDS & set(f.name.split("_")) or f.name == END]


def window_measures() -> list[str]:
    """The measures that depend on the window's length, not only on the cell: the counts
    and the extremes, in the summary's order."""
    kinds = {*count_measures(), *extreme_measures()}
    return [f.name for f in fields(RunSummary) if f.name in kinds]


def window_kind(measure: str) -> str | None:
    """``a count`` or ``an extreme`` if ``measure`` depends on the window, else None."""
    if measure in count_measures():
        return "a count"
    return "an extreme" if measure in extreme_measures() else None


def windows_apart(a: Scenario, b: Scenario) -> list[tuple[str, Any, Any]]:
    """The window settings on which ``a`` and ``b`` differ: (key, a's value, b's value).
    A warm-up of ``auto`` on either side differs even from ``auto``: MSER-5 cuts each run
    where its own output settles, so two points (of different policies or settings) count
    over windows of different lengths."""
    from cell.scenario.run_length import RunLength

    out: list[tuple[str, Any, Any]] = []
    la, lb = RunLength.of(a.run), RunLength.of(b.run)
    if la != lb:  # run.parts's numbers, or where hours come in, the lengths in words
        out.append(("parts", a.run.parts, b.run.parts) if la.unit == lb.unit == "part" else
                   ("length", str(la), str(lb)))
    wa, wb = a.run.warmup_parts, b.run.warmup_parts
    if wa != wb or AUTO in (wa, wb):
        out.append(("warmup_parts", wa, wb))
    return out


def setting(key: str) -> str:
    """How a window setting is named: ``run.parts``, ``run length``."""
    return "run length" if key == "length" else f"run.{key}"


def pair_apart(sweep: Sweep, pair: Pair) -> list[tuple[str, Any, Any]]:
    """:func:`windows_apart` of a pair's point and the point it is compared with (a
    warm-up of ``auto`` differs between them)."""
    return windows_apart(sweep.points[pair.point].scenario, sweep.points[pair.versus].scenario)


def window_warning(sweep: Sweep) -> str | None:
    """One line if some of the sweep's paired comparisons have points whose counts and
    extremes are over different windows (naming the settings), else None."""
    pairs = sweep.pairs()
    apart = [d for d in (pair_apart(sweep, p) for p in pairs) if d]
    if not apart:
        return None
    settings = [s for d in apart for s in d]  # (key, the point's value, its partner's)

    def side(key: str, i: int) -> str:
        return ", ".join(show(v) for v in distinct(s[i] for s in settings if s[0] == key))

    keys = [k for k in WINDOW_KEYS if any(s[0] == k for s in settings)]
    what = "; ".join(f"{setting(k)} {side(k, 1)} against {side(k, 2)}" for k in keys)
    auto = (f" (auto: {AUTO_WHY}, so no two points share a window)"
            if any(AUTO in s[1:] for s in settings) else "")
    return (f"{len(apart)} of {len(pairs)} paired comparisons are between points that run "
            f"over different windows ({what}{auto}): their {WINDOW_MEASURES_TEXT} are not "
            "comparable and are left out of differences.csv; compare the rates, or give the "
            "points the same window")


def suggest_window(va: object, vb: object) -> str:
    """A value valid for both (``--set`` sets it for both): the larger number, the fixed
    warm-up when the other is ``auto``, or ``N`` (said to be a fixed number) when both are
    ``auto``: no number is known before the runs, MSER-5 choosing one per run."""
    numbers = [v for v in (va, vb) if isinstance(v, int)]
    return str(max(numbers)) if numbers else "N"


def comparison_window_warning(sweep: Sweep) -> str | None:
    """``cell compare``'s :func:`window_warning`: one line if A's and B's counts and extremes
    are over different windows, else None."""
    from cell.experiments.sweep.spec import comparison_sides

    (la, a), (lb, b) = comparison_sides(sweep)
    differ = windows_apart(a.scenario, b.scenario)
    if not differ:
        return None
    said = {"parts": "runs {} parts", "length": "runs {}", "warmup_parts": "has run.warmup_parts {}"}
    what = "; ".join(f"{la} {said[k].format(va)}, {lb} {vb}" for k, va, vb in differ)
    if any(AUTO in (va, vb) for _, va, vb in differ):
        what += f" (auto: {AUTO_WHY}, so {la}'s and {lb}'s windows differ in length)"
    sets = " ".join("--set run.hours=H" if k == "length" else  # H hours for both
                    f"--set run.{k}={suggest_window(va, vb)}" for k, va, vb in differ)
    if any(va == vb == AUTO for _, va, vb in differ):
        sets += ", N a fixed number of parts"
    if any(k == "length" for k, _, _ in differ):
        sets += ", H the hours of both"
    return (f"{what}: {WINDOW_MEASURES_TEXT} are not comparable; compare the rates, or give "
            f"both the same window ({sets})")
