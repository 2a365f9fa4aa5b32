"""``learned``: a decision function trained on the cell (thesis §7.3's "AI system at the heart of
the adaptive controller"), as a plug-in policy (docs/rl.md, "The learned controller").

A residual policy: the thesis's adaptive decision (:func:`cell.sim.policies.adaptive.adaptive_plan`,
the same look-ahead) with the input belt's two commanded speeds, after LO and after the cycle,
each scaled by ``exp(y)``, ``y`` the output of a small network (one tanh layer) of what the
controller sees (:data:`FEATURES`, scaled); the plan is then mapped into the feasible set as the
environment maps an agent's action (:class:`cell.rl.actions.ActionMap`), so no plan it makes is
refused.  Its weights are a small JSON file in the package (``cell/rl/weights/learned.json``),
written by ``make learn`` (:mod:`cell.rl.train`, CMA-ES); running it needs numpy only.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from cell.rl.actions import ActionMap, action_of
from cell.sim.policies.adaptive import Adaptive
from cell.sim.policies.base import CellConstants, CellView, Plan

WEIGHTS = Path(__file__).resolve().parent / "weights" / "learned.json"
#: What the network reads, each divided by its scale: the input belt's speed (over nominal),
#: the next part's lag and distance (over the nominal cycle and the belt's length; -1: none in
#: sight), the output belt's gap (over the spacing), and a constant.
FEATURES = ("input_speed", "next_a", "next_b", "output_gap", "bias")
#: The network's outputs: the logarithms of the input belt's two speed factors.
OUTPUTS = ("input_after_lo", "input_next")
#: Hidden units of the network.
HIDDEN = 4
#: The largest speed factor's logarithm (a factor between 1/e and e).
MOST = 1.0


def size() -> int:
    """How many numbers the network has."""
    n = len(FEATURES)
    return HIDDEN * n + HIDDEN + len(OUTPUTS) * HIDDEN


def unpack(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    n, h = len(FEATURES), HIDDEN
    theta = np.asarray(theta, dtype=np.float64)
    return (theta[:h * n].reshape(h, n), theta[h * n:h * n + h],
            theta[h * n + h:].reshape(len(OUTPUTS), h))


def load_weights(path: Path = WEIGHTS) -> np.ndarray:
    """The committed weights (zeros: the adaptive decision itself, if none are committed)."""
    if not path.is_file():
        return np.zeros(size())
    theta = np.array(json.loads(path.read_text(encoding="utf-8"))["theta"], dtype=np.float64)
    if theta.shape != (size(),):
        raise ValueError(f"{path}: {theta.size} weights, the network has {size()}")
    return theta


class Learned(Adaptive):
    """``learned``: the adaptive decision, its input belt steered by the trained network."""

    name = "learned"

    def __init__(self, k: CellConstants, controller: Any, file: object = None,
                 theta: np.ndarray | None = None):
        super().__init__(k, controller, file)
        self.w1, self.b1, self.w2 = unpack(load_weights() if theta is None else theta)
        self.map = ActionMap(k)
        self.scale = np.array([k.v_nom, k.cycle_nom, k.input_length, k.spacing, 1.0])

    def features(self, view: CellView, v: float) -> np.ndarray:
        nxt = view.next_part(self.k.timing.r1_pre.time(v), v)
        gap = view.output_gap()
        x = np.array([v, -1.0 if nxt is None else nxt[0], -1.0 if nxt is None else nxt[1],
                      -1.0 if gap is None else gap, 1.0]) / self.scale
        return x

    def plan(self, view: CellView) -> Plan:
        base = super().plan(view)
        y = MOST * np.tanh(self.w2 @ np.tanh(self.w1 @ self.features(view, base.input_speed)
                                             + self.b1))
        if not y.any():
            return base
        a = action_of(base)
        a[6] *= math.exp(y[0])  # input_after_lo
        a[7] *= math.exp(y[1])  # input_next
        return self.map.to_plan(a, base.input_speed)
