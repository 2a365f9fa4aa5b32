"""Control policies: the thesis's two (``non-adaptive``, §6.3; ``adaptive``, §5.3)
and any other registered with :func:`cell.scenario.registry.register`."""

from cell.sim.policies.base import (
    Accounting,
    CellConstants,
    CellView,
    MotionTimeAccounting,
    Plan,
    Policy,
)

__all__ = ["Accounting", "CellConstants", "CellView", "MotionTimeAccounting", "Plan", "Policy"]
