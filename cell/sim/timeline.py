"""Where the time goes: each piece of equipment's states over the run (states.csv), and
the measures made of them (docs/model.md, "When equipment fails").

The robot is ``down`` (failed: waiting for a crew or being repaired), in ``maintenance``,
``busy`` (in motion), ``waiting`` (up and still, a part on its way to B on the input belt)
or ``idle`` (up and still, nothing on the input belt), in that order of precedence.  A belt
is ``down`` or ``running`` (``stopped``, up at speed 0, is the word for a belt a controller
halts; none of the built-in ones does); the sensor ``down`` or ``up``.  OEE's work unit
(:mod:`cell.sim.oee`) splits the robot's up-and-still time further: ``blocked`` while the
output belt is down, ``starved`` otherwise.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import numpy as np

ROBOT_STATES = ("down", "maintenance", "busy", "waiting", "idle")
#: Instants closer than this are one instant (the rounding of summed leg times).
GRAIN_S = 1e-6


def union(starts: np.ndarray, ends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Intervals [start, end) merged where they overlap or touch, in time order."""
    keep = ends > starts
    s, e = starts[keep], ends[keep]
    if not s.size:
        return s, e
    order = np.argsort(s, kind="stable")
    s, e = s[order], np.maximum.accumulate(e[order])
    new = np.empty(s.size, dtype=bool)
    new[0] = True
    new[1:] = s[1:] > e[:-1]
    last = np.append(np.flatnonzero(new)[1:] - 1, s.size - 1)
    return s[new], e[last]


def _inside(t: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Whether each instant lies in one of the merged intervals."""
    if not starts.size:
        return np.zeros(t.size, dtype=bool)
    k = np.searchsorted(starts, t, side="right") - 1
    return (k >= 0) & (t < ends[np.maximum(k, 0)])


def states(horizon: float, layers: Sequence[tuple[str, np.ndarray, np.ndarray]],
           rest: str) -> list[tuple[str, float, float]]:
    """(state, from, to) over [0, horizon]: each instant takes the first layer (name,
    starts, ends) it lies in, else ``rest``; consecutive equal states merged."""
    merged = [(name, *union(np.clip(s, 0.0, horizon), np.clip(e, 0.0, horizon)))
              for name, s, e in layers]
    cuts = np.unique(np.concatenate([[0.0, horizon], *[np.concatenate([s, e])
                                                        for _, s, e in merged]]))
    cuts = cuts[(cuts >= 0.0) & (cuts <= horizon)]
    if cuts.size > 1:  # instants a rounding apart are one (a leg's end and the next's start)
        apart = np.concatenate([[True], np.diff(cuts) > GRAIN_S])
        apart[-1] = True
        cuts = cuts[apart]
        if cuts.size > 2 and cuts[-1] - cuts[-2] <= GRAIN_S:
            cuts = np.delete(cuts, -2)
    if cuts.size < 2:
        return []
    mid = 0.5 * (cuts[:-1] + cuts[1:])
    label = np.full(mid.size, len(layers), dtype=np.int64)
    for i in range(len(merged) - 1, -1, -1):
        _, s, e = merged[i]
        label[_inside(mid, s, e)] = i
    change = np.flatnonzero(np.diff(label)) + 1
    first = np.concatenate([[0], change])
    last = np.concatenate([change, [mid.size]])
    names = [name for name, _, _ in layers] + [rest]
    return [(names[label[a]], float(cuts[a]), float(cuts[b]))
            for a, b in zip(first.tolist(), last.tolist())]


def fractions(rows: list[tuple[str, float, float]], horizon: float,
              names: Sequence[str]) -> dict[str, float]:
    """Each state's share of the horizon."""
    total = dict.fromkeys(names, 0.0)
    for state, a, b in rows:
        total[state] = total.get(state, 0.0) + (b - a)
    return {k: (v / horizon if horizon > 0 else float("nan")) for k, v in total.items()}


def rows(equipment: str, states_: list[tuple[str, float, float]]) -> Iterator[tuple[str, str, float, float]]:
    """states.csv's rows of one piece of equipment."""
    for state, a, b in states_:
        yield equipment, state, a, b
