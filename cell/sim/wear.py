"""Motor wear from how hard each cycle drives the joints (thesis §7.2; SPEC §10).

A joint's *stress* during a move is its step rate over its rated (peak) maximum at the
move's load, S = |steps| / t / R(load) (§6.1: R is linear in the load).  Life against
stress is the inverse power law of accelerated-life testing (Nelson 1990, *Accelerated
Testing*, ch. 2): a Weibull characteristic life η(S) = η0 · (S0 / S)^p, with η0 the
rated life at the reference stress S0 (the nominal 75 % of rated output, §7.2) and p
the exponent.  A varying stress is carried by the cumulative exposure model (Nelson
1990, ch. 10): ε(t) = ∫ dt / η(S(t)), and the motor fails when ε reaches E^(1/β) with
E ~ Exp(1), i.e. F(t) = 1 − exp(−ε(t)^β): Weibull of shape β in the exposure.  A joint
that does not move in a move takes no exposure from it (the clock is the joint's
operating time), so p = 0 is life in hours of motion whatever the speed, and p = 1 is
life in steps (the plain rolling-bearing case: L10h ∝ 1/n at a given load).

Within a move the step rate is constant, so a move's exposure is closed-form:
t · (S/S0)^p / η0 = c · t^(1−p) with c = (|steps| / (R S0))^p / η0.  The simulated
robot times a stretch of moves (a :class:`~cell.arm.motors.Segment`) by one velocity, each
move taking max(ℓ u, t_min) with u = 1/v: between two breakpoints of u the exposure of
a stretch is A u^(1−p) + B per joint, exact.  :class:`SegmentWear` keeps A and B at
every breakpoint, so a cycle's exposure costs a bisection and a power per stretch
(:class:`CycleWear`), never a pass over the moves.

The robot is a series system of its five motors: it stops at the first motor to wear
out, which is replaced, its exposure starting again from zero (:mod:`cell.sim.wear_clock`).
The other four keep their wear, so in the long run each motor's place is a renewal process
and the robot's mean time between stops is :func:`renewal_mtbf_h`.
"""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cell.arm.motors import Segment, max_rates

if TYPE_CHECKING:
    from cell.arm.steptable import StepTable
    from cell.sim.robot import RobotTiming

HOUR_S = 3600.0
#: The stretches of a cycle, in the order a plan gives their times (cell.arm.steptable.SEGMENTS).
STRETCHES = ("r1_pre", "r1_post", "r2", "r3_pre", "r3_post", "r4")


@dataclass(frozen=True)
class WearModel:
    """The life–stress model's named values (the ``wear:`` section)."""

    exponent: float = 1.0
    """p of the inverse power law η(S) = η0 (S0/S)^p."""
    rated_life_h: float = 5000.0
    """η0: a motor's Weibull characteristic life, hours of motion at the reference stress."""
    reference_stress: float = 0.75
    """S0: the stress the rated life is quoted at (step rate over the rated maximum)."""
    shape: float = 2.0
    """β: the Weibull shape in the exposure (above 1: wear-out)."""

    def rate_per_h(self, stress: ArrayLike) -> NDArray[np.float64]:
        """1/η(S) per hour of motion; 0 where the joint does not move (S = 0)."""
        s = np.asarray(stress, dtype=float)
        out = np.zeros_like(s)
        moving = s > 0
        out[moving] = (s[moving] / self.reference_stress) ** self.exponent / self.rated_life_h
        return out

    def life_h(self, stress: float) -> float:
        """η(S) in hours: the characteristic life at a constant stress S > 0."""
        return self.rated_life_h * (self.reference_stress / stress) ** self.exponent


def exposure(durations_s: ArrayLike, stress: ArrayLike, model: WearModel) -> NDArray[np.float64]:
    """ε = Σ t_k / η(S_k) of a piecewise-constant stress profile (moves × joints broadcast):
    the cumulative exposure model summed exactly over intervals of constant stress."""
    t = np.asarray(durations_s, dtype=float)
    rate = model.rate_per_h(stress)
    if rate.ndim > t.ndim:
        t = t.reshape(t.shape + (1,) * (rate.ndim - t.ndim))
    return np.sum(t / HOUR_S * rate, axis=0)


def failure_probability(eps: ArrayLike, model: WearModel) -> NDArray[np.float64]:
    """F = 1 − exp(−ε^β): the probability of having worn out by exposure ε."""
    return -np.expm1(-np.asarray(eps, dtype=float) ** model.shape)


def draw_thresholds(rng: np.random.Generator, n: int, model: WearModel) -> NDArray[np.float64]:
    """n exposures at which motors wear out: E^(1/β), E ~ Exp(1)."""
    return rng.exponential(1.0, n) ** (1.0 / model.shape)


def series_life_h(lives_h: ArrayLike, shape: float) -> float:
    """Characteristic life of motors in series, each Weibull(β) with its own η_j:
    S(t) = exp(−Σ (t/η_j)^β) = exp(−(t/η)^β) with η = (Σ η_j^−β)^(−1/β)."""
    inv = np.asarray(lives_h, dtype=float)
    total = float(np.sum(np.where(np.isfinite(inv), inv, np.inf) ** -shape))
    return math.inf if total == 0 else total ** (-1.0 / shape)


def renewal_mtbf_h(lives_h: ArrayLike, shape: float) -> float:
    """Long-run mean time between stops of motors in series, each replaced alone when it wears
    out: motor j's place is a renewal process of mean η_j Γ(1 + 1/β), and the robot stops at
    their summed rates, so MTBF = 1 / Σ_j 1 / (η_j Γ(1 + 1/β)) (inf: no motor wears).
    Not the mean η Γ(1 + 1/β) of :func:`series_life_h` (five new motors' first stop), which
    is longer."""
    lives = np.asarray(lives_h, dtype=float)
    rate = float(np.sum(1.0 / lives[np.isfinite(lives)])) / math.gamma(1.0 + 1.0 / shape)
    return math.inf if rate == 0 else 1.0 / rate


# --------------------------------------------------------------------------- per stretch
class SegmentWear:
    """Exposure of a stretch of moves per joint, as a function of the stretch's velocity.

    Move k of the stretch takes t_k(u) = max(ℓ_k u, t_min_k), u = 1/v (as
    :class:`~cell.arm.motors.Segment` times it).  Joint j's exposure is
    Σ_k c_jk t_k^(1−p): with the breakpoints u_k = t_min_k / ℓ_k sorted, on
    [u_(i−1), u_i) the first i moves are free and the rest motor-limited, so the
    exposure is A_i u^(1−p) + B_i, A_i and B_i kept here for every i.
    """

    __slots__ = ("timing", "peak_rates", "_ub", "_a", "_b", "_q", "_seen", "_tbreak", "_tfix",
                 "_lfree", "_seen_interval")

    def __init__(self, timing: Segment, lengths_in: ArrayLike, min_times_s: ArrayLike,
                 steps: ArrayLike, rated_steps_s: ArrayLike, model: WearModel):
        ell = np.asarray(lengths_in, dtype=float)
        tmin = np.asarray(min_times_s, dtype=float)
        counts = np.abs(np.asarray(steps, dtype=float))
        rated = np.asarray(rated_steps_s, dtype=float)
        p = model.exponent
        self.timing = timing
        self._q = 1.0 - p
        self._seen: tuple[float, list[float]] = (math.nan, [])
        self._seen_interval = (math.nan, 0)
        # c_jk t^(1-p): zero for a joint that does not move, whatever p
        c = np.zeros_like(counts)
        moving = counts > 0
        c[moving] = (counts[moving] / (rated[moving] * model.reference_stress)) ** p
        c /= model.rated_life_h * HOUR_S  # t in s, exposure in hours of rated life
        # a move's exposure a second, c t^(-p), is at its most at its floor t_min (p >= 0)
        with np.errstate(divide="ignore"):
            per_s = np.where(c > 0, c * np.broadcast_to(tmin[:, None], c.shape) ** -p, 0.0)
        self.peak_rates: list[float] = per_s.max(axis=0, initial=0.0).tolist()
        """Each joint's most exposure a second of the stretch, whatever its time (inf: a
        move of no floor time wears it)."""
        free = ell > 0
        fixed = _power_sum(c[~free], tmin[~free], self._q)
        ell, tmin, c = ell[free], tmin[free], c[free]
        order = np.argsort(tmin / ell, kind="stable")
        ell, tmin, c = ell[order], tmin[order], c[order]
        self._ub: list[float] = (tmin / ell).tolist()
        free_a = np.vstack([np.zeros((1, 5)), np.cumsum(c * ell[:, None] ** self._q, axis=0)])
        limited = _powers(c, tmin, self._q)
        lim_b = np.vstack([np.cumsum(limited[::-1], axis=0)[::-1], np.zeros((1, 5))])
        self._a: list[tuple[float, ...]] = [tuple(row) for row in free_a.tolist()]
        self._b: list[tuple[float, ...]] = [tuple(row) for row in (lim_b + fixed).tolist()]
        # the timing's own breakpoints, in the same order: a stretch's time finds its
        # interval in one bisection (cell.arm.motors.Segment.velocity's)
        if not np.array_equal(np.asarray(timing._ub), np.asarray(self._ub)):
            raise ValueError("the stretch's moves are not the timing segment's")
        self._tbreak, self._tfix, self._lfree = timing._tbreak, timing._tfix, timing._lfree

    def at_velocity(self, v: float) -> list[float]:
        """Exposure per joint (5 floats) of the stretch run at velocity v (inf: every move at
        its floor).  Plain floats: a handful of them cost less than one numpy operation."""
        u = 0.0 if math.isinf(v) else 1.0 / v
        i = bisect_right(self._ub, u)
        if u == 0.0:
            return list(self._b[i])
        x = u ** self._q
        return [a * x + b for a, b in zip(self._a[i], self._b[i])]

    def interval(self, time_s: float) -> int:
        """Which of the stretch's intervals of u ``time_s`` falls in (i: its first i moves
        free, the rest at their floor), found as :meth:`at_time` finds it."""
        seen = self._seen_interval
        if seen[0] == time_s:
            return seen[1]
        j = bisect_left(self._tbreak, time_s)
        self._seen_interval = (time_s, j)
        return j

    def at_time(self, time_s: float) -> list[float]:
        """Exposure per joint of the stretch taking ``time_s`` (its motor floor at least): the
        interval of u found as :meth:`cell.arm.motors.Segment.velocity` finds it, u = 1/v there.
        The last answer is kept, since most stretches take the same time cycle after cycle."""
        seen = self._seen
        if seen[0] == time_s:
            return seen[1]
        j = bisect_left(self._tbreak, time_s)
        lfree = self._lfree[j]
        if lfree <= 0:
            out = list(self._b[j])
        else:
            x = ((time_s - self._tfix[j]) / lfree) ** self._q
            out = [a * x + b for a, b in zip(self._a[j], self._b[j])]
        self._seen = (time_s, out)
        return out


def _powers(c: NDArray[np.float64], t: NDArray[np.float64], q: float) -> NDArray[np.float64]:
    """c_jk t_k^q, 0 where c is 0 (a joint at rest, or a move of no time)."""
    out = np.zeros_like(c)
    used = c > 0
    out[used] = c[used] * np.broadcast_to(t[:, None], c.shape)[used] ** q
    return out


def _power_sum(c: NDArray[np.float64], t: NDArray[np.float64], q: float) -> NDArray[np.float64]:
    return _powers(c, t, q).sum(axis=0) if len(t) else np.zeros(5)


# --------------------------------------------------------------------------- per cycle
class CycleWear:
    """A cycle's exposure per joint from its six stretch times (a policy's plan)."""

    def __init__(self, table: StepTable, timing: RobotTiming, model: WearModel):
        self.model = model
        ell, tp = table.velocity_lengths, table.peak_min_times
        rated = max_rates(table.path.load_oz, table.motors, 1.0)
        rows = table.segment_rows()
        self.stretches = tuple(
            SegmentWear(getattr(timing, name), ell[rows[name]], tp[rows[name]],
                        table.steps[rows[name]], rated[rows[name]], model)
            for name in STRETCHES)
        self._last: tuple[tuple[float, ...], list[float]] | None = None
        # speed: docs/performance.md#wear-by-interval
        self._by_interval: dict[tuple[int, ...], list[float]] | None = \
            {} if model.exponent == 1.0 else None
        """With p = 1 (life in steps) a stretch's A u^0 + B is A + B whatever its time within
        an interval: a cycle's exposure, looked up by its stretches' intervals."""

    def of_times(self, times_s: Sequence[float]) -> list[float]:
        """Exposure per joint (5 floats) of one cycle whose stretches take ``times_s``
        (r1_pre … r4).  A repeated cycle (the fixed robot's) is looked up, not computed again."""
        key = tuple(times_s)
        last = self._last
        if last is not None and last[0] == key:
            return last[1]
        known = self._by_interval
        if known is None:
            out = self._computed(key)
        else:
            intervals = tuple(w.interval(t) for w, t in zip(self.stretches, key, strict=True))
            hit = known.get(intervals)
            if hit is None:
                hit = known[intervals] = self._computed(key)
            out = hit
        self._last = (key, out)
        return out

    @property
    def peak_rates(self) -> list[float]:
        """Each joint's most exposure a second of any cycle (a bound: a cycle of d seconds
        wears joint j by at most d times this)."""
        return [max(r) for r in zip(*(w.peak_rates for w in self.stretches))]

    # speed: docs/performance.md#kept-cycles
    def of_many(self, times_s: Sequence[Sequence[float]]) -> NDArray[np.float64]:
        """(n, 5): :meth:`of_times` of each of n cycles, the same floats.  With p = 1 the
        stretches' intervals are found for all the cycles at once (``searchsorted`` finds what
        :meth:`SegmentWear.interval`'s bisection finds) and each interval's exposure looked
        up (computed once, as :meth:`of_times` would)."""
        known = self._by_interval
        if known is None or not len(times_s):
            return np.array([self.of_times(t) for t in times_s], dtype=float).reshape(-1, 5)
        times = np.array(times_s, dtype=float)
        cols = [np.searchsorted(w._tbreak, times[:, s], side="left")
                for s, w in enumerate(self.stretches)]
        code = cols[0]
        for col, w in zip(cols[1:], self.stretches[1:]):
            code = code * (len(w._tbreak) + 1) + col
        _, first, inverse = np.unique(code, return_index=True, return_inverse=True)
        table = []
        for i in first.tolist():
            intervals = tuple(int(col[i]) for col in cols)
            hit = known.get(intervals)
            if hit is None:
                hit = known[intervals] = self._computed(tuple(times_s[i]))
            table.append(hit)
        return np.array(table, dtype=float)[inverse.reshape(-1)]

    def _computed(self, times_s: tuple[float, ...]) -> list[float]:
        e = [w.at_time(t) for w, t in zip(self.stretches, times_s, strict=True)]
        return [a + b + c + d + f + g for a, b, c, d, f, g in zip(*e)]
