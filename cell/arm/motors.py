"""Stepper drives and move times (thesis §6.1; docs/model.md).

Each joint's motor has a maximum step rate linear in the carried load, between
its no-load and full-load figures.  Nominal operation runs the motors at 75 % of
that (§7.2), with the peak available on request.  A move's time is set by its
slowest joint: for a requested tip velocity v and move length ℓ the time is
ℓ / v, unless some joint would then exceed its rate, in which case that joint
runs at its rate and the tip slows down (§6.1).

Everything here is a pure, vectorised function of arrays of moves, so a
regime's time for a velocity is one numpy sum.
"""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cell.plumbing.errors import InfeasibleError
from cell.plumbing.types import Five


@dataclass(frozen=True)
class Motors:
    """The five stepper drives (§6.1): base, shoulder, elbow, wrist pitch, wrist roll."""

    steps_per_rad: Five = (1125.0, 1125.0, 672.0, 241.0, 241.0)
    """Motor (half-)steps per radian of joint motion."""
    max_rate_no_load_rad_s: Five = (0.4194527, 0.36, 0.82, 2.02, 2.02)
    max_rate_full_load_rad_s: Five = (0.37, 0.15, 0.23, 1.31, 1.31)
    full_load_oz: float = 16.0
    nominal_fraction: float = 0.75
    """Nominal operation at 75 % of rated output, peak on request (§7.2)."""


def max_rates(load_oz: ArrayLike, motors: Motors, fraction: float = 1.0) -> NDArray[np.float64]:
    """Maximum step rates (..., 5) in steps/s at each load, times ``fraction``.

    Linear in the load between the no-load and full-load speeds (§6.1);
    ``fraction = motors.nominal_fraction`` gives the nominal rates.
    """
    load = np.asarray(load_oz, dtype=float)[..., None]
    k = np.asarray(motors.steps_per_rad)
    no_load = np.asarray(motors.max_rate_no_load_rad_s) * k
    full = np.asarray(motors.max_rate_full_load_rad_s) * k
    return fraction * (no_load + (full - no_load) * load / motors.full_load_oz)


def min_move_times(steps: ArrayLike, load_oz: ArrayLike, motors: Motors,
                   fraction: float = 1.0) -> NDArray[np.float64]:
    """Shortest time of each move: its slowest joint at its (fractional) maximum rate."""
    counts = np.abs(np.asarray(steps, dtype=float))
    return np.max(counts / max_rates(load_oz, motors, fraction), axis=-1)


def move_times(lengths_in: ArrayLike, min_times_s: ArrayLike,
               velocity_in_s: float | ArrayLike) -> NDArray[np.float64]:
    """t = max(ℓ / v, t_min) per move (§6.1): the requested tip velocity unless a motor limits it."""
    v = np.asarray(velocity_in_s, dtype=float)
    if np.any(v <= 0):
        raise InfeasibleError(f"tip velocity must be positive, got {velocity_in_s!r}")
    return np.maximum(np.asarray(lengths_in, dtype=float) / v, np.asarray(min_times_s))


def velocity_for_time(lengths_in: ArrayLike, min_times_s: ArrayLike, time_s: float) -> float:
    """The tip velocity v whose moves Σ max(ℓ/v, t_min) take exactly ``time_s``.

    Raises :class:`InfeasibleError` if ``time_s`` is below the motors' minimum.
    See :class:`Segment`, which keeps the breakpoints for repeated queries.
    """
    if not np.any(np.asarray(lengths_in, dtype=float) > 0):
        raise InfeasibleError("a regime with no length has no tip velocity")
    return Segment(lengths_in, min_times_s).velocity(time_s)


class Segment:
    """Times of a run of moves, t(u) = Σ max(ℓ_k u, t_min_k) with u = 1/v.

    Built once from per-move lengths and minimum times; afterwards each query is
    a scalar bisection (microseconds), as the simulation needs.
    """

    __slots__ = ("length_in", "floor_s", "_ub", "_lfree", "_tfix", "_tbreak", "_seen")
    #: What a segment is rebuilt from (:meth:`saved`, :meth:`of_saved`: the timing's disk cache).
    SAVED = ("length_in", "floor_s", "_ub", "_lfree", "_tfix", "_tbreak")

    def __init__(self, lengths_in: ArrayLike, min_times_s: ArrayLike):
        ell = np.asarray(lengths_in, dtype=float)
        tmin = np.asarray(min_times_s, dtype=float)
        if ell.shape != tmin.shape or np.any(ell < 0) or np.any(tmin < 0):
            raise ValueError("lengths and minimum times must be matching non-negative arrays")
        self.length_in = float(ell.sum())
        """Total length (path or belt travel) of the moves."""
        self.floor_s = float(tmin.sum())
        """Shortest possible time: every move at its slowest joint's maximum rate."""
        moving = ell > 0
        # Zero-length moves always take their t_min; the others have a breakpoint:
        # move k is motor-limited while u < t_min_k / ℓ_k.
        fixed = float(tmin[~moving].sum())
        ell, tmin = ell[moving], tmin[moving]
        ub = tmin / ell
        order = np.argsort(ub, kind="stable")
        ub, ls, ts = ub[order], ell[order], tmin[order]
        # With u in [ub[j-1], ub[j]) moves 0..j-1 are free (time ℓ u), j.. limited.
        self._ub: list[float] = ub.tolist()
        self._lfree: list[float] = np.concatenate([[0.0], np.cumsum(ls)]).tolist()
        self._tfix: list[float] = (fixed + np.concatenate(
            [np.cumsum(ts[::-1])[::-1], [0.0]])).tolist()
        # t at each breakpoint, increasing: inverts t(u) by bisection.
        self._tbreak: list[float] = [self._tfix[j] + self._lfree[j] * u
                                     for j, u in enumerate(self._ub)]
        self._seen = (math.nan, math.nan)
        """The last velocity asked and its time (:meth:`time`)."""

    def saved(self) -> dict[str, Any]:
        """What the segment is rebuilt from (:data:`SAVED`), by name."""
        return {name: getattr(self, name) for name in self.SAVED}

    @classmethod
    def of_saved(cls, saved: dict[str, Any]) -> Segment:
        """The segment :meth:`saved` gave ``saved``."""
        segment = cls.__new__(cls)
        for name in cls.SAVED:
            setattr(segment, name, saved[name])
        segment._seen = (math.nan, math.nan)
        return segment

    def time(self, velocity: float) -> float:
        """Σ max(ℓ/v, t_min): the moves' time at tip (or belt) velocity v > 0."""
        seen = self._seen  # speed: docs/performance.md#last-time
        if seen[0] == velocity:
            return seen[1]
        u = 1.0 / velocity
        j = bisect_right(self._ub, u)
        t = self._tfix[j] + self._lfree[j] * u
        self._seen = (velocity, t)
        return t

    def velocity(self, time_s: float) -> float:
        """The velocity v whose moves take exactly ``time_s`` (inverse of :meth:`time`)."""
        if time_s < self.floor_s * (1 - 1e-12):
            raise InfeasibleError(f"{time_s:.4f} s is below the motors' minimum "
                                  f"of {self.floor_s:.4f} s")
        j = bisect_left(self._tbreak, time_s)
        if self._lfree[j] <= 0:
            return float("inf")
        return self._lfree[j] / (time_s - self._tfix[j])

    def max_tracking_velocity(self) -> float:
        """Fastest velocity at which no move is motor-limited (min ℓ/t_min)."""
        return 1.0 / self._ub[-1] if self._ub else float("inf")
