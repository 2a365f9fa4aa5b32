"""Stepper drives and move times (thesis §6.1; SPEC §4).

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

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cell.errors import InfeasibleError
from cell.scenario import Motors


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
    steps = np.abs(np.asarray(steps, dtype=float))
    return np.max(steps / max_rates(load_oz, motors, fraction), axis=-1)


def move_times(lengths_in: ArrayLike, min_times_s: ArrayLike,
               velocity_in_s: float | ArrayLike) -> NDArray[np.float64]:
    """t = max(ℓ / v, t_min) per move (§6.1): the requested tip velocity unless a motor limits it."""
    v = np.asarray(velocity_in_s, dtype=float)
    if np.any(v <= 0):
        raise InfeasibleError(f"tip velocity must be positive, got {velocity_in_s!r}")
    return np.maximum(np.asarray(lengths_in, dtype=float) / v, np.asarray(min_times_s))


def velocity_for_time(lengths_in: ArrayLike, min_times_s: ArrayLike, time_s: float) -> float:
    """The tip velocity v whose moves Σ max(ℓ/v, t_min) take exactly ``time_s``.

    The total is convex, piecewise linear and increasing in u = 1/v, so the
    answer is exact: sort the moves by the u at which their motor stops
    limiting them and find the piece that holds ``time_s``.  Raises
    :class:`InfeasibleError` if ``time_s`` is below the motors' minimum.
    """
    ell = np.asarray(lengths_in, dtype=float)
    tmin = np.asarray(min_times_s, dtype=float)
    floor = float(tmin.sum())
    if time_s < floor * (1 - 1e-12):
        raise InfeasibleError(f"{time_s:.4f} s is below the motors' minimum of {floor:.4f} s")
    moving = ell > 0
    if not moving.any():
        raise InfeasibleError("a regime with no length has no tip velocity")
    # For u below u_i = tmin_i/ℓ_i move i is motor-limited (time tmin_i).
    u_break = np.where(moving, tmin / np.where(moving, ell, 1.0), np.inf)
    order = np.argsort(u_break)
    ub, l_sorted, t_sorted = u_break[order], ell[order], tmin[order]
    # With u in [ub[j-1], ub[j]) moves 0..j-1 run at ℓ u, the rest at tmin.
    ell_free = np.concatenate([[0.0], np.cumsum(l_sorted)])
    t_fixed = np.concatenate([[0.0], np.cumsum(t_sorted[::-1])])[::-1]
    u = (time_s - t_fixed) / np.where(ell_free > 0, ell_free, np.nan)
    lo = np.concatenate([[0.0], ub])
    hi = np.concatenate([ub, [np.inf]])
    ok = (u >= lo - 1e-15) & (u <= hi + 1e-15) & np.isfinite(u) & (u > 0)
    j = int(np.flatnonzero(ok)[-1]) if ok.any() else len(ub)
    return float(1.0 / u[j])
