"""Homogeneous transformations (thesis §2.2, eq. 2.5-2.7, 2.16, 2.25).

Every function is vectorised: angles and offsets may be arrays, and the result
then has shape ``(*angle.shape, 4, 4)``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

Frame = NDArray[np.float64]  # (..., 4, 4)


def _eye(shape: tuple[int, ...]) -> Frame:
    out = np.zeros(shape + (4, 4))
    out[..., [0, 1, 2, 3], [0, 1, 2, 3]] = 1.0
    return out


def rot(axis: str, theta: ArrayLike) -> Frame:
    """Rot(axis, θ), θ in radians (eq. 2.5 x, 2.6 y, 2.7 z)."""
    theta = np.asarray(theta, dtype=float)
    c, s = np.cos(theta), np.sin(theta)
    out = _eye(theta.shape)
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    out[..., i, i] = c
    out[..., i, j] = -s
    out[..., j, i] = s
    out[..., j, j] = c
    return out


def trans(x: ArrayLike, y: ArrayLike = 0.0, z: ArrayLike = 0.0) -> Frame:
    """Trans(a, b, c) (eq. 2.16)."""
    x, y, z = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (x, y, z)))
    out = _eye(x.shape)
    out[..., 0, 3], out[..., 1, 3], out[..., 2, 3] = x, y, z
    return out


def inverse(t: Frame) -> Frame:
    """Closed-form inverse of a homogeneous transform (eq. 2.25).

    Rows n, o, a of the rotation become columns, and the position is
    (-p·n, -p·o, -p·a).
    """
    t = np.asarray(t, dtype=float)
    out = np.zeros_like(t)
    r = t[..., :3, :3]
    p = t[..., :3, 3]
    out[..., :3, :3] = np.swapaxes(r, -1, -2)
    out[..., :3, 3] = -np.einsum("...ji,...j->...i", r, p)
    out[..., 3, 3] = 1.0
    return out


def position(t: Frame) -> NDArray[np.float64]:
    """The p column of a transform, shape (..., 3)."""
    return np.asarray(t)[..., :3, 3]
