"""The phase-plane minimum-time planner (Shin & McKay 1983; SPEC §9).

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

Both integrations are Heun's method (second order) on the grid.  The time is
T = Σ 2Δs / (ṡ_i + ṡ_{i+1}), the formula SPEC §9 fixes for comparisons.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cell.errors import CellError

from .rows import PathRows, acceleration_rows, torque_rows, velocity_rows

__all__ = ["NoMotionError", "PathRows", "Profile", "acceleration_rows", "plan", "torque_rows",
           "velocity_limit", "velocity_rows"]

Array = NDArray[np.float64]

#: |a| below this fraction of the row's largest |a| along the path counts as
#: zero: the row then bounds ṡ only (a zero-inertia point).
ZERO_INERTIA = 1e-9


class NoMotionError(CellError):
    """No admissible motion along the path under the given bounds."""


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
def _bound_lists(rows: PathRows) -> tuple[list, list, bool]:
    """Per grid point, the coefficients (k0, k1, k2) of its bounds u ≤ k0 + k1 ṡ + k2 ṡ²
    (from α > 0) and u ≥ ... (from α < 0), as Python lists for the scalar loop.

    Halves that bound nothing at a point get ±inf; halves that bound nothing
    anywhere are dropped.  The flag says whether any bound has a ṡ term.
    """
    alpha, b0, b1, b2 = _halves(rows)
    safe = np.where(alpha == 0, 1.0, alpha)
    out = []
    for mask, fill in ((alpha > 0, np.inf), (alpha < 0, -np.inf)):
        cols = mask.any(axis=0)
        m = mask[:, cols]
        k0 = np.where(m, b0[:, cols] / safe[:, cols], fill)
        k1 = np.where(m, b1[:, cols] / safe[:, cols], 0.0)
        k2 = np.where(m, b2[:, cols] / safe[:, cols], 0.0)
        out.append([list(zip(r0, r1, r2)) for r0, r1, r2 in
                    zip(k0.tolist(), k1.tolist(), k2.tolist())])
    return out[0], out[1], bool(np.any(b1))


def _umax(bounds: list, x: float, sd: float) -> float:
    best = math.inf
    for k0, k1, k2 in bounds:
        v = k0 + k1 * sd + k2 * x
        if v < best:
            best = v
    return best


def _umin(bounds: list, x: float, sd: float) -> float:
    best = -math.inf
    for k0, k1, k2 in bounds:
        v = k0 + k1 * sd + k2 * x
        if v > best:
            best = v
    return best


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

    def times(self) -> Array:
        """(N,) time at each grid point."""
        dt = 2.0 * np.diff(self.s) / (self.sdot[:-1] + self.sdot[1:])
        return np.concatenate([[0.0], np.cumsum(dt)])


def _where(s: Array, i: int) -> str:
    return f"s = {s[i]:.4f}"


def plan(rows: PathRows, sdot_start: float = 0.0, sdot_end: float = 0.0) -> Profile:
    """The minimum-time profile under ``rows`` from ``sdot_start`` to ``sdot_end``.

    Raises :class:`NoMotionError` (a :class:`CellError`) naming where motion
    stops being possible: the limit curve at zero, a start or end state above
    it, or no way to keep moving.
    """
    s = np.asarray(rows.s, float)
    n = len(s)
    if n < 2 or np.any(np.diff(s) <= 0):
        raise NoMotionError("the path grid must have at least 2 increasing points")
    limit = velocity_limit(rows)
    inner = limit[1:-1] <= 0
    if inner.any():
        i = int(np.flatnonzero(inner)[0]) + 1
        raise NoMotionError(f"no motion possible at {_where(s, i)}: the bounds leave no path "
                            "velocity (the velocity-limit curve is zero there)")
    if sdot_start > limit[0] * (1 + 1e-9) or sdot_end > limit[-1] * (1 + 1e-9):
        raise NoMotionError("the start or end path velocity is above the velocity-limit curve")
    mvc = limit * limit
    ups, downs, _ = _bound_lists(rows)
    sq = math.sqrt
    ds = np.diff(s).tolist()
    mvc_l = mvc.tolist()

    # Backward: maximum deceleration from the end, never above the limit curve.
    xb = [0.0] * n
    xb[-1] = sdot_end ** 2
    for i in range(n - 2, -1, -1):
        d, x1 = ds[i], xb[i + 1]
        l1 = _umin(downs[i + 1], x1, sq(x1))
        if l1 == -math.inf:
            xb[i] = mvc_l[i]
            continue
        xp = min(x1 - 2.0 * d * l1, mvc_l[i])
        xp = max(xp, 0.0)
        l0 = _umin(downs[i], xp, sq(xp))
        x0 = x1 - d * (l1 + l0) if l0 != -math.inf else mvc_l[i]
        xb[i] = min(x0, mvc_l[i])
        if xb[i] <= 0.0 and i > 0:
            raise NoMotionError(f"no motion possible at {_where(s, i)}: the arm cannot brake "
                                "in time to stay on the path")

    # Forward: maximum acceleration from the start, never above the backward curve.
    xf = [0.0] * n
    phase = np.zeros(n - 1, dtype=np.int8)
    xf[0] = min(sdot_start ** 2, xb[0])
    for i in range(n - 1):
        d, x0 = ds[i], xf[i]
        cap = xb[i + 1]
        u0 = _umax(ups[i], x0, sq(x0))
        xp = x0 + 2.0 * d * u0 if u0 != math.inf else math.inf
        if xp >= cap:
            x1 = cap
        else:
            if xp < 0.0:
                raise NoMotionError(f"no motion possible at {_where(s, i)}: the bounds leave "
                                    "no acceleration to keep moving along the path")
            u1 = _umax(ups[i + 1], xp, sq(xp))
            x1 = min(x0 + d * (u0 + u1), cap)
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
    time_s = float(np.sum(2.0 * np.diff(s) / speed))
    return Profile(s, sdot, limit, phase, time_s, _switches(s, phase))


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
