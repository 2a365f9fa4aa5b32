"""Minimum-time motion along the transfer path (Shin & McKay 1983).

``cell.arm.mintime.planner`` is the phase-plane algorithm itself, on plain arrays;
``cell.arm.mintime.regimes`` applies it to the cell's freely moving regimes, R II
and R IV, under a :class:`~cell.arm.mintime.regimes.PlannerBounds`.
"""
