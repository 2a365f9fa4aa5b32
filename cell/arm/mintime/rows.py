"""Joint bounds along a path as rows of the paper's reduced form (Shin & McKay 1983, eq. 11b):

    lo ≤ a(s) u + b(s) ṡ² + e(s) ṡ + c(s) ≤ hi,   u = s̈,

one row per joint and kind of bound, on a grid of s (the planner's input).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from cell.plumbing.types import Array


@dataclass(frozen=True)
class PathRows:
    """Bounds on the path acceleration along a grid, in the reduced form above.

    Every array has one entry (or one row) per grid point.
    """

    s: Array
    """(N,) grid, increasing from 0 to 1."""
    a: Array
    """(N, m) coefficient of s̈ (the paper's M for a torque row)."""
    b: Array
    """(N, m) coefficient of ṡ² (Q)."""
    e: Array
    """(N, m) coefficient of ṡ (R: friction and the motor line)."""
    c: Array
    """(N, m) constant (S: gravity)."""
    lo: Array
    """(N, m) lower bound."""
    hi: Array
    """(N, m) upper bound."""
    sdot_max: Array = field(default=None)  # type: ignore[arg-type]
    """(N,) direct cap on ṡ from the joint velocity bounds (inf: none)."""

    def __post_init__(self) -> None:
        if self.sdot_max is None:
            object.__setattr__(self, "sdot_max", np.full(len(self.s), np.inf))

    @staticmethod
    def join(*parts: PathRows) -> PathRows:
        """All rows of several sets on the same grid; the tightest ṡ cap."""
        cat = lambda name: np.hstack([getattr(p, name) for p in parts])  # noqa: E731
        return PathRows(parts[0].s, cat("a"), cat("b"), cat("e"), cat("c"), cat("lo"), cat("hi"),
                        np.min([p.sdot_max for p in parts], axis=0))


def velocity_rows(s: ArrayLike, dq: ArrayLike, qdot_max: ArrayLike) -> PathRows:
    """|q'_j ṡ| ≤ q̇max_j: no acceleration rows, only the cap ṡ ≤ min_j q̇max_j / |q'_j|."""
    s, dq = np.asarray(s, float), np.asarray(dq, float)
    with np.errstate(divide="ignore"):
        cap = np.min(np.asarray(qdot_max, float) / np.abs(dq), axis=1)
    empty = np.zeros((len(s), 0))
    return PathRows(s, empty, empty, empty, empty, empty, empty, cap)


def acceleration_rows(s: ArrayLike, dq: ArrayLike, ddq: ArrayLike,
                      qddot_max: ArrayLike) -> PathRows:
    """|q'_j s̈ + q''_j ṡ²| ≤ q̈max_j."""
    dq, ddq = np.asarray(dq, float), np.asarray(ddq, float)
    amax = np.broadcast_to(np.asarray(qddot_max, float), dq.shape)
    return PathRows(np.asarray(s, float), dq, ddq, np.zeros_like(dq), np.zeros_like(dq),
                    -amax, amax.copy())


def torque_rows(s: ArrayLike, q: ArrayLike, dq: ArrayLike, ddq: ArrayLike, rnea: Callable,
                tau_max: ArrayLike, *, viscous: ArrayLike | None = None,
                line_slope: ArrayLike | None = None) -> PathRows:
    """The paper's reduced dynamics (eq. 11b) as rows, one per joint.

    ``rnea(q, qd, qdd, friction=False, gravity=...)`` is the rigid-body inverse
    dynamics.  M = J q' (a), Q = J q'' + c(q', q') (b), R = K q' plus the
    torque-speed line's slope τ_s/ω_f times q' (e), S = g(q) (c); bounded by
    ±τ_max.
    """
    q, dq, ddq = (np.asarray(v, float) for v in (q, dq, ddq))
    zero = np.zeros_like(q)
    a = rnea(q, zero, dq, friction=False, gravity=False)
    b = rnea(q, dq, ddq, friction=False, gravity=False)
    c = rnea(q, zero, zero, friction=False, gravity=True)
    e = np.zeros_like(q)
    if viscous is not None:
        e = e + np.asarray(viscous, float) * dq
    if line_slope is not None:
        e = e + np.asarray(line_slope, float) * dq
    t = np.broadcast_to(np.asarray(tau_max, float), q.shape)
    return PathRows(np.asarray(s, float), a, b, e, c, -t, t.copy())
