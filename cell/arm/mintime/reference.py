"""TOPP-RA (the ``toppra`` package) on the same path and bounds: the
independent implementation the planner is checked and benchmarked against
(docs/model.md).  Same spline, same grid, same time formula."""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cell.plumbing.errors import CellError


def toppra_profile(s_way: ArrayLike, q_way: ArrayLike, grid: ArrayLike, *,
                   qdot_max: ArrayLike | None = None, qddot_max: ArrayLike | None = None,
                   inv_dyn: Callable | None = None, tau_max: ArrayLike | None = None,
                   bc_type: str = "not-a-knot") -> tuple[NDArray[np.float64], float]:
    """(ṡ at the grid points, T = Σ 2Δs/(ṡ_i + ṡ_{i+1})) from toppra, rest to rest.

    Acceleration and torque bounds are collocated at the grid points (toppra's
    ``Collocation``), as the planner enforces them.
    """
    import toppra
    import toppra.constraint as tc

    logging.getLogger("toppra").setLevel(logging.ERROR)
    q_way = np.asarray(q_way, float)
    path = toppra.SplineInterpolator(np.asarray(s_way, float), q_way, bc_type=bc_type)
    cons = []
    if qdot_max is not None:
        v = np.asarray(qdot_max, float)
        cons.append(tc.JointVelocityConstraint(np.column_stack([-v, v])))
    if qddot_max is not None:
        a = np.asarray(qddot_max, float)
        cons.append(tc.JointAccelerationConstraint(
            np.column_stack([-a, a]), discretization_scheme=tc.DiscretizationType.Collocation))
    if inv_dyn is not None:
        t = np.asarray(tau_max, float)
        cons.append(tc.JointTorqueConstraint(inv_dyn, np.column_stack([-t, t]),
                                             np.zeros(len(t)),
                                             discretization_scheme=tc.DiscretizationType.Collocation))
    grid = np.asarray(grid, float)
    algo = toppra.algorithm.TOPPRA(cons, path, gridpoints=grid, solver_wrapper="seidel")
    out = algo.compute_parameterization(0.0, 0.0)
    sd = out[1]
    if sd is None:
        raise CellError("toppra found no parameterisation")
    sd = np.asarray(sd, float)
    return sd, float(np.sum(2.0 * np.diff(grid) / (sd[:-1] + sd[1:])))
