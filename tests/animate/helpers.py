"""What the animation's tests share: the window shown, and facts computed here rather
than by the animation's code (belt travel by fine numerical integration of the recorded
speed history, the scenario's named points, what a drawn collection shows)."""

from __future__ import annotations

import numpy as np
from scipy.integrate import cumulative_trapezoid  # type: ignore[import-untyped]

from cell.reporting.animation.scene import Scene, window
from cell.scenario.schema import Scenario

FIRST, COUNT = 2, 6


def integrated(history: np.ndarray, until_s: float, dt: float = 1e-3):  # noqa: ANN201
    """X(t) of a belt by the trapezoid rule on a fine grid, speeds looked up the plain way."""
    grid = np.arange(0.0, until_s + dt, dt)
    speed = np.empty_like(grid)
    for start, v in history:                  # each change holds from its instant on
        speed[grid >= start] = v
    x = cumulative_trapezoid(speed, grid, initial=0.0)
    return lambda t: np.interp(t, grid, x)


def sample_times(scenes: list[Scene]) -> np.ndarray:
    t0, t1 = window(scenes, FIRST, COUNT)
    return np.linspace(t0 - 40.0, t1, 400)


def named_points(s: Scenario) -> dict[str, np.ndarray]:
    p = s.path
    b, g = np.array(p.bot_in), np.array(p.g_in)
    return {"B": b, "F": np.array(p.f_in), "G": g, "K": np.array(p.eot_in),
            "LO": np.array([b[0] + p.lo_from_bot_in, b[1], p.pick_height_in]),
            "TD": np.array([g[0], g[1] + p.td_from_g_in, p.place_height_in])}


def output_reach(panel) -> float:  # noqa: ANN001
    """The farthest y (in) of output belt drawn: the strip's end or the close-up's top."""
    return max(panel.parts_out.axes.get_xlim()[1], panel.parts.axes.get_ylim()[1])


def square_centres(collection) -> np.ndarray:  # noqa: ANN001
    """Centres of the squares a PolyCollection draws."""
    return np.array([p.vertices[:4].mean(axis=0) for p in collection.get_paths()]).reshape(-1, 2)

