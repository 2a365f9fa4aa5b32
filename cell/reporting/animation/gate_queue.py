"""A buffer in the animation (docs/layout.md "Seen"): which parts stood at the gate, and where
the parts still waiting stand at an instant, queued at the buffer's pitch behind the gate at B.
Plain numpy on :class:`~cell.reporting.animation.scene.AnimationInput`'s arrays."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray


def buffered(d: Any, scenario: Any) -> dict[str, Any]:
    """A buffer's :class:`AnimationInput` fields: each part's wait and the pitch (none
    without a ``buffer:`` with places)."""
    b = scenario.buffer
    if b is None or not b.places or "buffer_wait_s" not in d:
        return {}
    pitch = b.pitch_in if b.pitch_in is not None else scenario.part.size_in
    return {"buffer_wait_s": d["buffer_wait_s"].to_numpy(dtype=float), "pitch_in": float(pitch)}


def waited_parts(data: Any) -> NDArray[np.bool_]:
    """(n,) the parts that stood at the buffer's gate (or behind it) before it let them go."""
    if data.buffer_wait_s is None:
        return np.zeros(len(data.part), dtype=bool)
    return data.buffer_wait_s > 0


def queue_x(scene: Any, t: float, x_free: NDArray[np.float64]
            ) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
    """The parts on the input belt before the gate lets them go, and their x at instant t:
    each moves with the belt (``x_free``, where it would be moving) until it closes up behind
    the parts still waiting ahead of it, ``pitch_in`` apart, the first at the gate at B
    (docs/layout.md "The buffer"); let go at its ``at_bot_s``, it moves on from B."""
    d = scene.data
    waited = waited_parts(d)
    queued = waited & (d.arrival_s <= t) & (t < d.at_bot_s)
    x = np.full(len(d.part), np.nan)
    if not queued.any():
        return queued, x
    idx = np.flatnonzero(queued)
    release = d.at_bot_s[idx]
    ahead = (release[None, :] < release[:, None]).sum(axis=1)  # first come, first let go
    x[idx] = np.minimum(x_free[idx], scene.b_xy[0] - ahead * d.pitch_in)
    return queued, x
