"""Figures laid out but not rasterised, for tests of what a figure says or which are drawn
(the ``unrendered`` fixture, in tests/conftest.py, puts :func:`unrendered_savefig` in place);
figures built but neither laid out nor rasterised (``unlaid``, likewise), for tests that read none."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

#: A PNG signature: what an unrendered figure's file holds (tests/reporting/test_figures.py reads
#: every figure as a real PNG).
STUB = b"\x89PNG\r\n\x1a\n"


def stub_file(fname: Any) -> None:
    """Write :data:`STUB` where a save would write its PNG."""
    if hasattr(fname, "write"):
        fname.write(STUB)
    else:
        Path(fname).write_bytes(STUB)


def unrendered_savefig(fig: Figure, fname: Any, *args: Any, **kwargs: Any) -> None:
    """Everything a save does but the pixels: the layout, the texts and ticks, and any warning
    they raise are met; the file holds :data:`STUB`."""
    fig.draw_without_rendering()
    stub_file(fname)


def unlaid_savefig(fig: Figure, fname: Any, *args: Any, **kwargs: Any) -> None:
    """The file a save writes, holding :data:`STUB`; the figure, built with all its artists,
    is not laid out (its layout is most of a save's time when nothing is rasterised)."""
    stub_file(fname)
