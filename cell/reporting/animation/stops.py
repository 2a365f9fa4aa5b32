"""A frame's stopped equipment (``failures:``, ``wear:``): marked, with its repair clock.

The robot stopped is drawn in red with what stopped it and when it is back; a stopped belt
says so beside its speed; a failed sensor under the robot's line.  While the robot is stopped
its arm stands where the stop caught it: :class:`OperatingClock` is the robot's clock with its
stops taken out, the clock its moves are timed on (parts.csv's regime times leave the stops out).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cell.sim.timeline import union

#: How a stop's cause reads on a frame.
STOP_WORDS = {"failure": "breakdown", "wear": "worn motor", "maintenance": "maintenance"}
DOWN_COLOUR = "#c0392b"


def duration(seconds: float) -> str:
    """A repair clock: h:mm:ss (or m:ss under an hour), rounded up to the second."""
    whole = max(0, math.ceil(seconds))
    hours, rest = divmod(whole, 3600)
    minutes, secs = divmod(rest, 60)
    return f"{hours}:{minutes:02d}:{secs:02d}" if hours else f"{minutes}:{secs:02d}"


def stop_lines(down: Mapping[str, tuple[str, float]]) -> dict[str, str]:
    """What a frame says of each stopped piece of equipment (name -> its words)."""
    out = {}
    for name, (cause, left) in down.items():
        what = STOP_WORDS.get(cause, cause)
        if name == "robot":
            out[name] = f"robot DOWN ({what}): back in {duration(left)}"
        elif name == "sensor":
            out[name] = f"sensor down: back in {duration(left)}"
        else:
            out[name] = f"STOPPED ({what}), back in {duration(left)}"
    return out


def mark_stops(down: Mapping[str, tuple[str, float]], texts: Mapping[str, Any],
               arm: Iterable[Any]) -> None:
    """Mark the stopped equipment on a frame whose texts and arm are already drawn."""
    texts["belts"].set_color(DOWN_COLOUR if "input_belt" in down or "output_belt" in down
                             else "black")
    if not down:
        return
    words = stop_lines(down)
    belts = texts["belts"].get_text().split("\n")
    for k, name in enumerate(("input_belt", "output_belt")):
        if name in words and k < len(belts):
            belts[k] += "  " + words[name]
    texts["belts"].set_text("\n".join(belts))
    if "robot" in words:
        texts["robot"].set_text(words["robot"])
        texts["robot"].set_color(DOWN_COLOUR)
        for line in arm:
            line.set_color(DOWN_COLOUR)
    if "sensor" in words:
        texts["robot"].set_text(texts["robot"].get_text() + "\n" + words["sensor"])


@dataclass(frozen=True)
class OperatingClock:
    """The robot's operating time: wall time less the robot's stops before it.

    ``operating`` is flat through a stop (the arm stands still) and ``wall`` is its inverse,
    giving for an operating instant the earliest wall instant that reaches it (a stop's
    start, not its end)."""

    start_s: NDArray[np.float64]
    """(k,) the stops' starts, sorted, overlapping stops merged."""
    end_s: NDArray[np.float64]
    """(k,) their ends."""

    @classmethod
    def of(cls, stops: Iterable[tuple[str, str, float, float]]) -> OperatingClock:
        """The clock of a run's stops, (equipment, cause, from_s, to_s): the robot's only."""
        spans = np.asarray([(a, b) for name, _, a, b in stops if name == "robot"],
                           dtype=float).reshape(-1, 2)
        return cls(*union(spans[:, 0], spans[:, 1]))

    @property
    def _down_before(self) -> NDArray[np.float64]:
        """(k + 1,) the stops' time before each stop, and in all."""
        return np.concatenate([[0.0], np.cumsum(self.end_s - self.start_s)])

    def operating(self, t: ArrayLike) -> NDArray[np.float64]:
        """The operating instant of each wall instant t."""
        t = np.asarray(t, dtype=float)
        if not len(self.start_s):
            return t
        cum = self._down_before
        k = np.searchsorted(self.start_s, t, side="right")
        inside = (k > 0) & (t < self.end_s[np.maximum(k - 1, 0)])
        frozen = self.start_s[np.maximum(k - 1, 0)] - cum[np.maximum(k - 1, 0)]
        return np.where(inside, frozen, t - cum[k])

    def wall(self, x: ArrayLike) -> NDArray[np.float64]:
        """The earliest wall instant whose operating instant is x."""
        x = np.asarray(x, dtype=float)
        if not len(self.start_s):
            return x
        cum = self._down_before
        k = np.searchsorted(self.start_s - cum[:-1], x, side="left")
        return x + cum[k]
