"""The figures' small promises: shared axes where asked, Fig. 13 of a few draws, Fig. 13/14's
file names after the arrivals' family."""

from __future__ import annotations

from cell.figures.style import new_figure


def test_panels_share_the_x_axis_only_where_asked():
    fig, (top, bottom) = new_figure(23, "shared", nrows=2, sharex=True)
    bottom.set_xlim(3.0, 7.0)
    assert top.get_xlim() == (3.0, 7.0)
    fig.draw_without_rendering()
    assert not any(t.get_visible() and t.get_text() for t in top.get_xticklabels())
    assert any(t.get_text() for t in bottom.get_xticklabels())
    _, (left, right) = new_figure(23, "apart", nrows=2)
    right.set_xlim(3.0, 7.0)
    assert left.get_xlim() != (3.0, 7.0)
