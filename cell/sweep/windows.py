"""The windows counts are taken over, and the paired comparisons they spoil.

A count of a run's summary (parts delivered, parts lost, spacings outside
tolerance, belt limits: its whole-number columns) is per run, after the warm-up,
so two points' counts compare only if both run the same ``run.parts`` with the
same ``run.warmup_parts``; their rates (parts/hr, actual cycle, IP) compare
whatever the windows.  ``cell compare`` and ``cell sweep`` both warn when a
paired comparison's points differ there, and leave its counts out of
``differences.csv``.
"""

from __future__ import annotations

from dataclasses import fields
from typing import TYPE_CHECKING, Any

from cell.records import RunSummary
from cell.sweep.options import distinct, show

if TYPE_CHECKING:
    from cell.scenario import Scenario
    from cell.sweep.spec import Pair, Sweep

#: The ``run`` settings that decide a count's window.
WINDOW_KEYS = ("parts", "warmup_parts")


def count_measures() -> list[str]:
    """The count columns of a run's summary: its whole-number measures but the warm-up's
    own length (``warmup_parts``, the window, not a count over it), in order."""
    return [f.name for f in fields(RunSummary) if isinstance(f.default, int)
            and not isinstance(f.default, bool) and f.name != "warmup_parts"]


def windows_apart(a: Scenario, b: Scenario) -> list[tuple[str, Any, Any]]:
    """The window settings on which ``a`` and ``b`` differ: (key, a's value, b's value)."""
    return [(key, getattr(a.run, key), getattr(b.run, key))
            for key in WINDOW_KEYS if getattr(a.run, key) != getattr(b.run, key)]


def pair_apart(sweep: Sweep, pair: Pair) -> list[tuple[str, Any, Any]]:
    """:func:`windows_apart` of a pair's point and the point it is compared with."""
    return windows_apart(sweep.points[pair.point].scenario, sweep.points[pair.versus].scenario)


def window_warning(sweep: Sweep) -> str | None:
    """One line if some of the sweep's paired comparisons have points whose counts are
    over different windows (naming the settings), else None."""
    pairs = sweep.pairs()
    apart = [d for d in (pair_apart(sweep, p) for p in pairs) if d]
    if not apart:
        return None
    settings = [s for d in apart for s in d]  # (key, the point's value, its partner's)

    def side(key: str, i: int) -> str:
        return ", ".join(show(v) for v in distinct(s[i] for s in settings if s[0] == key))

    keys = [k for k in WINDOW_KEYS if any(s[0] == k for s in settings)]
    what = "; ".join(f"run.{k} {side(k, 1)} against {side(k, 2)}" for k in keys)
    return (f"{len(apart)} of {len(pairs)} paired comparisons are between points that count "
            f"over different windows ({what}): their counts (parts delivered, parts lost, "
            "spacings outside tolerance, ...) are not comparable and are left out of "
            "differences.csv; compare the rates, or give the points the same window")
