"""The joint-step table: the robot's moves as motor steps (thesis §6.1).

The path is solved once (eq. 6.7 and the inverse kinematics at every point);
what the simulated robot needs is, for each move, the steps of each joint, the
move's length, its regime, the load carried and the LO/TD events.  Steps are
counted from absolute step positions (round(θ·k)), so rounding never drifts:
the steps of a regime add up to its joint travel.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from cell.arm.motors import Motors, min_move_times
from cell.arm.path import REGIMES, CellGeometry, TransferPath, build_path
from cell.plumbing.cache import memo

#: The stretches of a cycle whose times a plan fixes: R I and R III split at LO
#: and TD (the grasp / release move ends the first half).
SEGMENTS = ("r1_pre", "r1_post", "r2", "r3_pre", "r3_post", "r4")

COLUMNS = ["point", "regime", "x_in", "y_in", "z_in",
           "theta1_deg", "theta2_deg", "theta3_deg", "theta4_deg", "theta5_deg",
           "steps1", "steps2", "steps3", "steps4", "steps5", "move_in", "load_oz", "event"]


@dataclass(frozen=True)
class StepTable:
    """Per-move steps of one transfer path; row i is the move arriving at point i."""

    path: TransferPath
    motors: Motors
    steps: NDArray[np.int64]
    """(N, 5) signed motor steps per move (row 0: zeros)."""

    @classmethod
    def from_path(cls, path: TransferPath, motors: Motors) -> StepTable:
        position = np.rint(path.q_rad * np.asarray(motors.steps_per_rad)).astype(np.int64)
        steps = np.vstack([np.zeros((1, 5), dtype=np.int64), np.diff(position, axis=0)])
        return cls(path, motors, steps)

    @classmethod
    def solve(cls, geometry: CellGeometry, motors: Motors) -> StepTable:
        """The path of ``geometry`` solved once per process (cached on its inputs)."""
        return _solved(geometry, motors)

    @property
    def move_in(self) -> NDArray[np.float64]:
        return self.path.move_in

    def regime_rows(self, regime: int | str) -> NDArray[np.bool_]:
        """Mask of the moves of one regime (1..4 or 'R1'..'R4'); row 0 is no move."""
        r = REGIMES.index(regime) + 1 if isinstance(regime, str) else int(regime)
        mask = self.path.regime == r
        mask[0] = False
        return mask

    def regime_points(self, regime: int | str) -> NDArray[np.intp]:
        """Indices of a regime's points, with the point it starts from."""
        rows = np.flatnonzero(self.regime_rows(regime))
        return np.arange(rows[0] - 1, rows[-1] + 1)

    def min_times(self, fraction: float = 1.0) -> NDArray[np.float64]:
        """(N,) each move at its slowest joint's rate × ``fraction`` (row 0: 0)."""
        return min_move_times(self.steps, self.path.load_oz, self.motors, fraction)

    @cached_property
    def peak_min_times(self) -> NDArray[np.float64]:
        return self.min_times(1.0)

    @cached_property
    def nominal_min_times(self) -> NDArray[np.float64]:
        return self.min_times(self.motors.nominal_fraction)

    def segment_rows(self) -> dict[str, NDArray[np.bool_]]:
        """Masks of the moves of each of :data:`SEGMENTS`."""
        idx = np.arange(self.path.n_points)
        lo, td = self.path.lo, self.path.td
        r1, r3 = self.regime_rows(1), self.regime_rows(3)
        return {"r1_pre": r1 & (idx <= lo), "r1_post": r1 & (idx > lo),
                "r2": self.regime_rows(2), "r3_pre": r3 & (idx <= td),
                "r3_post": r3 & (idx > td), "r4": self.regime_rows(4)}

    @cached_property
    def velocity_lengths(self) -> NDArray[np.float64]:
        """(N,) what each move's velocity is measured on (§6.1): the belt's travel while
        tracking (R I along B → F, R III along G → K; the path divides the belt
        equally, §4.2), the path length in R II and R IV."""
        xyz = self.path.xyz_in
        out = self.move_in.copy()
        for regime in (1, 3):
            rows = self.regime_rows(regime)
            pts = self.regime_points(regime)
            start, end = xyz[pts[0], :2], xyz[pts[-1], :2]
            direction = (end - start) / np.linalg.norm(end - start)
            out[rows] = np.abs(np.diff(xyz[:, :2], axis=0)[rows[1:]] @ direction)
        return out

    def regime_length(self, regime: int | str) -> float:
        return float(self.move_in[self.regime_rows(regime)].sum())

    def regime_min_time(self, regime: int | str, nominal: bool = False) -> float:
        """Σ of a regime's moves at the joints' peak (or nominal) rates."""
        t = self.nominal_min_times if nominal else self.peak_min_times
        return float(t[self.regime_rows(regime)].sum())

    def to_frame(self) -> pd.DataFrame:
        """The table with the documented column names (``cell path``)."""
        p = self.path
        deg = np.degrees(p.q_rad)
        data = {"point": np.arange(p.n_points),
                "regime": [REGIMES[r - 1] for r in p.regime],
                "x_in": p.xyz_in[:, 0], "y_in": p.xyz_in[:, 1], "z_in": p.xyz_in[:, 2]}
        data.update({f"theta{j + 1}_deg": deg[:, j] for j in range(5)})
        data.update({f"steps{j + 1}": self.steps[:, j] for j in range(5)})
        data.update({"move_in": p.move_in, "load_oz": p.load_oz, "event": p.events})
        return pd.DataFrame(data, columns=COLUMNS)


@memo(maxsize=16)
def _solved(geometry: CellGeometry, motors: Motors) -> StepTable:
    return StepTable.from_path(build_path(geometry), motors)
