"""The cell as a reinforcement-learning environment and a learned controller (docs/rl.md).

:class:`CellEnv` (also ``gymnasium.make("cell/TransferCell-v0", scenario=...)`` once
``cell.rl`` is imported) steps the simulated cell from one decision of its controller to the
next; ``learned`` is a plug-in policy whose decision function was trained on the cell
(:mod:`cell.rl.learned`, ``make learn``).
"""

from __future__ import annotations

from cell.rl.env import ENV_ID, CellEnv

__all__ = ["ENV_ID", "CellEnv"]
