"""``cell animate``, a long input belt: the strip keeps the belt and its parts visible.

Drawn at equal aspect, a belt of 10,000 in (a far drop point, or the default two nominal
cycles of belt when the robot's cycle is hours long) was a band thinner than a pixel and its
parts were not drawn at all.  Pixels of the rendered frame are counted here."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.colors import to_rgb

from cell.reporting.animation.movie import simulate_scenes
from cell.reporting.animation.scene import INPUT, parts_at
from cell.scenario.schema import Scenario


def _strip_pixels(scenario: Scenario, t_s: float) -> tuple[np.ndarray, int]:
    """The input strip's pixels (rows, columns, RGB) at ``t_s``, and how many parts it holds."""
    from cell.reporting.animation.render import build_figure, draw_frame

    scenes = simulate_scenes(scenario, ["adaptive"], 1, 2)
    fig, panels = build_figure(scenes, dpi=100.0)
    draw_frame(panels[0], t_s)
    fig.canvas.draw()
    rgba = np.asarray(fig.canvas.buffer_rgba())
    box = panels[0].parts_in.axes.bbox
    rows = slice(rgba.shape[0] - int(box.y1) + 1, rgba.shape[0] - int(box.y0) - 1)
    on_belt = int((parts_at(scenes[0], t_s).where == INPUT).sum())
    return rgba[rows, int(box.x0) + 1:int(box.x1) - 1, :3] / 255.0, on_belt


def _rows_of(pixels: np.ndarray, colour: str, tol: float = 0.02) -> int:
    hit = np.all(np.abs(pixels - np.array(to_rgb(colour))) < tol, axis=-1)
    return int(hit.any(axis=1).sum())


def _columns_of(pixels: np.ndarray, colour: str, tol: float = 0.12) -> int:
    hit = np.all(np.abs(pixels - np.array(to_rgb(colour))) < tol, axis=-1)
    return int(hit.any(axis=0).sum())


@pytest.mark.parametrize("length_in", [135.5232, 4_000.0, 10_000.0])
def test_the_input_belt_and_its_parts_are_visible_however_long(scenario: Scenario,
                                                                length_in: float) -> None:
    """The belt band fills at least a quarter of the strip's height, and every part on the
    belt shows at least a pixel column of its colour."""
    from cell.reporting.animation.render import BELT_COLOUR, PART_COLOUR

    long = scenario.with_overrides({"belts.input_length_in": length_in})
    first_arrival = 24.85  # the default seed's first part; both parts are dropped by 60 s
    t_s = first_arrival + 40.0
    pixels, on_belt = _strip_pixels(long, t_s)
    assert on_belt >= 1
    assert _rows_of(pixels, BELT_COLOUR) >= pixels.shape[0] / 4
    assert _columns_of(pixels, PART_COLOUR) >= on_belt
