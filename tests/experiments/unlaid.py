"""The ``unlaid`` fixture: a report's figures drawn (their axes, lines and texts made) but
neither laid out nor rasterised, each PNG file holding only the signature.  For tests of
where a report goes and what its tables, CSVs and text say: laying out a figure costs about
half a second and a sweep's report has one a measure.  The figures themselves, laid out and
rendered, are tests/reporting's (``unrendered`` lays them out without the pixels)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from matplotlib.figure import Figure

from tests.reporting.conftest import STUB


def unlaid_savefig(fig: Figure, fname: Any, *args: Any, **kwargs: Any) -> None:
    """The file a save would write, holding :data:`STUB`; the figure not laid out."""
    if hasattr(fname, "write"):
        fname.write(STUB)
    else:
        Path(fname).write_bytes(STUB)


@pytest.fixture
def unlaid(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(Figure, "savefig", unlaid_savefig)
