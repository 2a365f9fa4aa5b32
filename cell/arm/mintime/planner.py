"""The phase-plane minimum-time planner (Shin & McKay 1983; docs/model.md).

Along a fixed path q(s), 0 ≤ s ≤ 1, every joint bound becomes a bound on the
path acceleration u = s̈ that depends on the state (s, ṡ).  Each bound is a
*row* of the paper's reduced form (its eq. 11b with M, Q, R, S):

    lo ≤ a(s) u + b(s) ṡ² + e(s) ṡ + c(s) ≤ hi

(a torque row has a = J q', b = J q'' + c(q', q'), e = K q' and c = g(q); an
acceleration row has a = q', b = q''; e carries viscous friction and the
motor's torque-speed line).  The planner works in x = ṡ², where dx/ds = 2u:

1. the velocity-limit curve: at each grid point the highest ṡ at which the
   rows still leave some u, found in closed form from every pair of rows
   (each pair gives a quadratic in ṡ, the paper's Figure 1) and capped by the
   joint velocity bounds; a row whose a vanishes (a zero-inertia point, a
   joint reversing along the path) bounds ṡ directly and needs no division;
2. maximum deceleration integrated backward from the end, never above the
   limit curve: wherever it meets the curve the curve takes over, which is
   where the switching points lie;
3. maximum acceleration integrated forward from the start, never above the
   backward curve: the result is the bang-bang profile (accelerate, ride the
   limit curve, decelerate) with its switching points.

Both integrations are Heun's method (second order) on the grid, with an implicit
Euler step where a drive settles on its torque balance within one step.  The time
is T = Σ 2Δs / (ṡ_i + ṡ_{i+1}), the formula docs/model.md fixes for comparisons: exact
where x is linear in s between grid points, which it is not where a fast drive
reaches top speed inside one step (O(Δs) each start and stop on a uniform grid);
:func:`path_grid` therefore grades the grid toward both ends.

Every step is IEEE arithmetic (+, −, ×, ÷, √, min, max) in a fixed order and the
sum is correctly rounded: the same rows give the same plan bit for bit, on every
run and whichever SIMD code paths numpy picks on the machine.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cell.plumbing.errors import NoMotionError
from cell.plumbing.types import Array

from .rows import PathRows, acceleration_rows, torque_rows, velocity_rows

__all__ = ["NoMotionError", "PathRows", "Profile", "acceleration_rows", "elapsed_s", "path_grid",
           "plan", "torque_rows", "velocity_limit", "velocity_rows"]


#: |a| below this fraction of the row's largest |a| along the path counts as
#: zero: the row then bounds ṡ only (a zero-inertia point).
ZERO_INERTIA = 1e-9

#: Width, in s, over which :func:`path_grid` grades the grid at each end (its steps grow
#: by 1 + 1/(GRADING_WIDTH (n − 1)) from one to the next).
GRADING_WIDTH = 0.01
#: The first step at each end, as a fraction of the step in the middle.
SMALLEST_STEP = 1e-3


def path_grid(n: int) -> Array:
    """n grid points on [0, 1]: uniform in the middle, graded geometrically toward both ends.

    The steps at each end start at ``SMALLEST_STEP`` of the middle step H (about
    1.15/(n − 1)) and grow by the factor 1 + 1/(GRADING_WIDTH (n − 1)) until they reach H.
    A rest-to-rest motion starts and stops there, and a drive that reaches top speed in
    far less than H (the MICROBOT's, in milliseconds) still gets grid points on its
    ramp: its share of the paper's T = ∫ dλ/μ (§4) is then accurate to O(H²), not O(H).  Doubling n
    halves every step, so grids of 460, 920, 1840, ... points refine one another.
    Products and sums only: the same points on every machine.
    """
    if n < 2:
        raise ValueError("a path grid needs at least 2 points")
    ratio = 1.0 + 1.0 / (GRADING_WIDTH * (n - 1))
    ramp, w = [], SMALLEST_STEP
    while w < 1.0:
        ramp.append(w)
        w *= ratio
    if 4 * len(ramp) > n - 1:        # too few points to grade
        return np.linspace(0.0, 1.0, n)
    steps = np.concatenate([ramp, np.ones(n - 1 - 2 * len(ramp)), ramp[::-1]])
    s = np.concatenate([[0.0], np.cumsum(steps)])
    return s / s[-1]


# --------------------------------------------------------------------------- limit curve
def _halves(rows: PathRows) -> tuple[Array, Array, Array, Array]:
    """Each row as two one-sided bounds α u ≤ β0 + β1 ṡ + β2 ṡ².

    α counts as zero (a zero-inertia point) when it is below ``ZERO_INERTIA`` of
    the row's largest |α| along the path plus its own β's size: a joint that
    does not move (q' at round-off) then bounds ṡ only, never u.  Halves whose
    α is zero and whose β cannot bind (β0 > 0, no ṡ terms) are dropped.
    """
    alpha = np.hstack([rows.a, -rows.a])
    b0 = np.hstack([rows.hi - rows.c, rows.c - rows.lo])
    b1 = np.hstack([-rows.e, rows.e])
    b2 = np.hstack([-rows.b, rows.b])
    if alpha.shape[1]:
        tol = ZERO_INERTIA * (np.max(np.abs(alpha), axis=0) + np.abs(b0) + np.abs(b1) + np.abs(b2))
        alpha = np.where(np.abs(alpha) <= tol, 0.0, alpha)
        idle = (alpha == 0) & (b0 > 0) & (np.abs(b1) <= ZERO_INERTIA * b0) \
            & (np.abs(b2) <= ZERO_INERTIA * b0)
        keep = ~idle.all(axis=0)
        alpha, b0, b1, b2 = alpha[:, keep], b0[:, keep], b1[:, keep], b2[:, keep]
    return alpha, b0, b1, b2


def _first_loss(c0: Array, c1: Array, c2: Array) -> Array:
    """Smallest y ≥ 0 beyond which c2 y² + c1 y + c0 turns negative (inf: never; 0: at once)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        scale = np.abs(c0) + np.abs(c1) + np.abs(c2)
        tiny = 1e-12 * np.where(scale > 0, scale, 1.0)
        disc = c1 * c1 - 4.0 * c2 * c0
        sq = np.sqrt(np.maximum(disc, 0.0))
        qq = -0.5 * (c1 + np.where(c1 >= 0, sq, -sq))
        r_a, r_b = qq / c2, c0 / qq
        r_lo, r_hi = np.minimum(r_a, r_b), np.maximum(r_a, r_b)
        linear = np.where(c1 < 0, -c0 / c1, np.inf)
        up = np.where((disc > 0) & (c1 < 0), r_lo, np.inf)      # convex: dips between roots
        down = r_hi                                              # concave: lost after the upper root
        out = np.where(np.abs(c2) <= tiny, linear, np.where(c2 > 0, up, down))
        out = np.where(np.isnan(out), np.inf, out)
        return np.where(c0 < -tiny, 0.0, np.maximum(out, 0.0))


def velocity_limit(rows: PathRows) -> Array:
    """(N,) the velocity-limit curve ṡ_max(s): the top of the admissible ṡ from rest.

    Above the first loss of admissibility the phase plane may open again (the
    paper's "islands"); the planner stays below, which is exact without
    friction and conservative with it.
    """
    alpha, b0, b1, b2 = _halves(rows)
    n = len(rows.s)
    limit = rows.sdot_max.astype(float).copy()
    if alpha.shape[1] == 0:
        return limit
    pos, neg, zer = alpha > 0, alpha < 0, alpha == 0
    # Rows with a = 0 bound ṡ directly: β(ṡ) ≥ 0.
    if zer.any():
        r = _first_loss(np.where(zer, b0, 1.0), np.where(zer, b1, 0.0), np.where(zer, b2, 0.0))
        limit = np.minimum(limit, r.min(axis=1))
    # Every upper bound (α_p > 0) against every lower bound (α_n < 0):
    # U_p ≥ L_n  ⇔  α_p β_n − α_n β_p ≥ 0, a quadratic in ṡ.
    cp, cn = pos.any(axis=0), neg.any(axis=0)
    if not (cp.any() and cn.any()):
        return limit
    ap = np.where(pos, alpha, 0.0)[:, cp, None]
    an = np.where(neg, alpha, 0.0)[:, None, cn]
    valid = pos[:, cp, None] & neg[:, None, cn]
    coef = [ap * bn[:, None, cn] - an * bp[:, cp, None] for bp, bn in ((b0, b0), (b1, b1), (b2, b2))]
    c0 = np.where(valid, coef[0], 1.0)
    if not np.any(b1):
        # No ṡ terms: the pair is linear in x = ṡ², lost beyond x = −c0/c2 when c2 < 0.
        c2 = np.where(valid, coef[2], 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            x = np.where(c2 < 0, -c0 / c2, np.inf)
        x = np.where(c0 < -1e-12 * (np.abs(c0) + np.abs(c2)), 0.0, x)
        r = np.sqrt(np.maximum(x, 0.0))
    else:
        r = _first_loss(c0, np.where(valid, coef[1], 0.0), np.where(valid, coef[2], 0.0))
    limit = np.minimum(limit, r.reshape(n, -1).min(axis=1))
    return limit


# --------------------------------------------------------------------------- integration
Bounds = list[tuple[float, ...]]


def _bound_lists(rows: PathRows, limit: Array) -> tuple[Bounds, Bounds]:
    """Per grid point, the bounds u ≤ k0 + k1 ṡ + k2 ṡ² (from α > 0) and u ≥ … (from α < 0)
    as flat tuples (k0, k1, k2, k0', k1', k2', …) for the scalar loop.

    Only bounds that can bind somewhere on 0 ≤ ṡ ≤ ṡ_max(s) are kept: one that another
    bound undercuts on that whole range (the difference is a quadratic in ṡ, checked at
    both ends and its vertex) is dropped, so that usually one bound a side remains.
    """
    alpha, b0, b1, b2 = _halves(rows)
    y = np.where(np.isfinite(limit), limit, np.nan)[:, None, None]
    out = []
    for sign in (1.0, -1.0):
        act = sign * alpha > 0
        cols = act.any(axis=0)
        act = act[:, cols]
        a = np.where(act, alpha[:, cols], 1.0)
        k = np.stack([b[:, cols] / a for b in (b0, b1, b2)], axis=-1)          # (N, c, 3)
        # d[i, j, j'] = sign (f_j − f_j') ≥ 0 on [0, ṡ_max]: bound j is never tighter than j'.
        d = sign * (k[:, :, None, :] - k[:, None, :, :])
        d0, d1, d2 = d[..., 0], d[..., 1], d[..., 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            yv = np.where(d2 > 0, -d1 / (2.0 * d2), 0.0)
            yv = np.clip(yv, 0.0, y)
            worst = np.minimum(np.minimum(d0, d0 + (d1 + d2 * y) * y), d0 + (d1 + d2 * yv) * yv)
            loose = (worst >= 0) & act[:, None, :]
        c = k.shape[1]
        later = np.arange(c)[:, None] > np.arange(c)[None, :]                 # j' before j
        tie = loose & np.swapaxes(loose, 1, 2)
        dominated = (loose & (~tie | later)).any(axis=2)
        keep = act & ~dominated
        order = np.argsort(~keep, axis=1, kind="stable")
        k = np.take_along_axis(k, order[:, :, None], axis=1)                  # kept ones first
        count = keep.sum(axis=1)
        side: Bounds = list(zip(*(k[:, 0, j].tolist() for j in range(3)))) if c else [()] * len(k)
        for i in np.flatnonzero(count != 1).tolist():
            side[i] = tuple(k[i, :count[i]].ravel().tolist())
        out.append(side)
    return out[0], out[1]


def _umax(b: tuple[float, ...], x: float, sd: float) -> float:
    if len(b) == 3:
        return b[0] + b[1] * sd + b[2] * x
    best = math.inf
    for j in range(0, len(b), 3):
        v = b[j] + b[j + 1] * sd + b[j + 2] * x
        best = min(best, v)
    return best


def _umin(b: tuple[float, ...], x: float, sd: float) -> float:
    if len(b) == 3:
        return b[0] + b[1] * sd + b[2] * x
    best = -math.inf
    for j in range(0, len(b), 3):
        v = b[j] + b[j + 1] * sd + b[j + 2] * x
        best = max(best, v)
    return best


def _advance(b: tuple[float, ...], bound: Callable[[tuple[float, ...], float, float], float],
             xk: float, uk: float, h: float, top: float) -> float:
    """x = ṡ² one step of signed length h along dx/ds = 2u (the paper's phase-plane
    trajectory, §4: eq. 11b divided by 11a), from xk where the bound gives uk, to the next
    point whose bounds are ``b``; never above ``top``.  Negative: stalled.

    Heun's method, unless the next point's bound has opposite signs at xk and at the
    predictor, or Heun ends below zero: then the step crosses a speed at which the bound
    vanishes (a drive on its torque-speed line reaching its torque balance within one step),
    where Heun overshoots and is unstable.  The implicit Euler step x = xk + 2h u(x), which
    settles on that speed however long the step, is then solved by bisection.
    """
    xp = xk + 2.0 * h * uk
    xq = min(max(xp, 0.0), top)
    u1 = bound(b, xq, math.sqrt(xq))
    x = xk + h * (uk + u1)
    if math.isfinite(u1) and (x < 0.0 or xq < top):
        u_here = bound(b, xk, math.sqrt(xk))
        if x < 0.0 or (u_here > 0.0) != (u1 > 0.0):
            x = _implicit_euler(b, bound, xk, h, u_here, (xq, 0.0, top), x)
    return min(x, top)


def _implicit_euler(b: tuple[float, ...], bound: Callable[[tuple[float, ...], float, float], float],
                    xk: float, h: float, u_here: float, ends: tuple[float, ...],
                    fallback: float) -> float:
    """The root y of g(y) = y − xk − 2h u(y) between xk and the first of ``ends`` on the side
    where it lies (below xk if g(xk) > 0) that brackets it.  None below: −1 (even at rest
    the bound slows the path, a stall); none above: ``fallback``."""
    def g(y: float) -> float:
        return y - xk - 2.0 * h * bound(b, y, math.sqrt(y))
    g_here = -2.0 * h * u_here
    if g_here == 0.0:
        return xk
    below = g_here > 0.0
    for end in ends:
        if (end < xk) != below or not math.isfinite(end):
            continue
        g_end = g(end)
        if (g_end > 0.0) == below:
            continue
        lo, hi, g_lo = end, xk, g_end
        for _ in range(64):
            mid = 0.5 * (lo + hi)
            g_mid = g(mid)
            if (g_mid < 0.0) == (g_lo < 0.0):
                lo, g_lo = mid, g_mid
            else:
                hi = mid
        return 0.5 * (lo + hi)
    return -1.0 if below else fallback


@dataclass(frozen=True)
class Profile:
    """The minimum-time profile ṡ(s) on the grid."""

    s: Array
    sdot: Array
    sdot_limit: Array
    """The velocity-limit curve."""
    phase: NDArray[np.int8]
    """(N-1,) per interval: +1 maximum acceleration, 0 on the limit curve, -1 maximum deceleration."""
    time_s: float
    switching_s: list[float]
    """Where the control switches between the phases (interval boundaries)."""


def _where(s: Array, i: int) -> str:
    return f"s = {s[i]:.4f}"


def _checked_limit(rows: PathRows, s: Array, sdot_start: float, sdot_end: float) -> Array:
    """The velocity-limit curve, once the grid and both end states are found admissible."""
    if len(s) < 2 or np.any(np.diff(s) <= 0):
        raise NoMotionError("the path grid must have at least 2 increasing points")
    limit = velocity_limit(rows)
    inner = limit[1:-1] <= 0
    if inner.any():
        i = int(np.flatnonzero(inner)[0]) + 1
        raise NoMotionError(f"no motion possible at {_where(s, i)}: the bounds leave no path "
                            "velocity (the velocity-limit curve is zero there)")
    if sdot_start > limit[0] * (1 + 1e-9) or sdot_end > limit[-1] * (1 + 1e-9):
        raise NoMotionError("the start or end path velocity is above the velocity-limit curve")
    return limit


def plan(rows: PathRows, sdot_start: float = 0.0, sdot_end: float = 0.0) -> Profile:
    """The minimum-time profile under ``rows`` from ``sdot_start`` to ``sdot_end``.

    Raises :class:`NoMotionError` (a :class:`CellError`) naming where motion
    stops being possible: the limit curve at zero, a start or end state above
    it, or no way to keep moving.
    """
    s = np.asarray(rows.s, float)
    n = len(s)
    limit = _checked_limit(rows, s, sdot_start, sdot_end)
    ups, downs = _bound_lists(rows, limit)
    sq = math.sqrt
    ds = np.diff(s).tolist()
    mvc_l = (limit * limit).tolist()

    # Backward: maximum deceleration from the end, never above the limit curve.
    xb = [0.0] * n
    xb[-1] = sdot_end ** 2
    for i in range(n - 2, -1, -1):
        x1 = xb[i + 1]
        l1 = _umin(downs[i + 1], x1, sq(x1))
        xb[i] = mvc_l[i] if l1 == -math.inf else _advance(downs[i], _umin, x1, l1, -ds[i], mvc_l[i])
        if xb[i] < 0.0 or (xb[i] == 0.0 and i > 0):
            raise NoMotionError(f"no motion possible at {_where(s, i)}: the arm cannot brake "
                                "in time to stay on the path")

    # Forward: maximum acceleration from the start, never above the backward curve.
    xf = [0.0] * n
    phase = np.zeros(n - 1, dtype=np.int8)
    xf[0] = min(sdot_start ** 2, xb[0])
    for i in range(n - 1):
        d, x0, cap = ds[i], xf[i], xb[i + 1]
        u0 = _umax(ups[i], x0, sq(x0))
        if u0 == math.inf or x0 + 2.0 * d * u0 >= cap:
            x1 = cap
        else:
            x1 = _advance(ups[i + 1], _umax, x0, u0, d, cap)
            if x1 < 0.0:
                raise NoMotionError(f"no motion possible at {_where(s, i)}: the bounds leave "
                                    "no acceleration to keep moving along the path")
        if x1 < cap * (1.0 - 1e-9):
            phase[i] = 1
        else:
            phase[i] = 0 if cap >= mvc_l[i + 1] * (1 - 1e-9) else -1
        xf[i + 1] = x1
    sdot = np.sqrt(np.maximum(np.asarray(xf), 0.0))
    speed = sdot[:-1] + sdot[1:]
    if np.any(speed <= 0):
        i = int(np.flatnonzero(speed <= 0)[0])
        raise NoMotionError(f"no motion possible at {_where(s, i)}: the path velocity is zero")
    return Profile(s, sdot, limit, phase, float(elapsed_s(s, sdot)[-1]), _switches(s, phase))


def elapsed_s(s: Array, sdot: Array) -> Array:
    """(N,) the time at each grid point from the start, t_0 = 0: the partial sums of
    T = Σ 2Δs / (ṡ_i + ṡ_{i+1}) (ṡ_i + ṡ_{i+1} > 0), each correctly rounded, as math.fsum
    rounds: the sums are exact in integers (every float is an integer over a power of two),
    so the last is ``time_s`` bit for bit on every machine, whatever the order of the terms."""
    ratios = [x.as_integer_ratio() for x in (2.0 * np.diff(s) / (sdot[:-1] + sdot[1:])).tolist()]
    den = max((d for _, d in ratios), default=1)      # powers of two: the largest is their lcm
    sums = itertools.accumulate(n * (den // d) for n, d in ratios)
    return np.array([0.0, *(total / den for total in sums)])   # int / int: correctly rounded


def _switches(s: Array, phase: NDArray[np.int8]) -> list[float]:
    """Grid points where the phase changes, ignoring runs of a single interval
    (the discrete profile ticking against a curved limit)."""
    if len(phase) == 0:
        return []
    change = np.flatnonzero(np.diff(phase) != 0) + 1
    starts = np.concatenate([[0], change])
    lengths = np.diff(np.concatenate([starts, [len(phase)]]))
    keep = starts[(lengths > 1) | (starts == 0) | (starts == len(phase) - 1)]
    vals = phase[keep]
    out = [float(s[k]) for j, k in enumerate(keep) if j > 0 and vals[j] != vals[j - 1]]
    return out
