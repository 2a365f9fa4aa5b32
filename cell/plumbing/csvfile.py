"""CSV rows written as records complete: the same bytes pandas would write.

Floats with a fixed format (``%.10g`` by default: enough to round-trip the
figures, identical on every run; a whole number with ``.0``, so pandas reads floats:
:func:`cell.plumbing.output.atomic.float_text`), NaN as an empty field, booleans as
``True``/``False``; quoting as the csv module's minimal quoting.  Used to stream
``parts.csv`` and ``belts.csv`` while the simulation runs, so memory stays flat.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from operator import attrgetter
from typing import Any, TextIO

from cell.plumbing.output.atomic import FLOAT_FORMAT, float_formatter, float_text


def cell_text(value: Any, float_format: str = FLOAT_FORMAT) -> str:
    """One field as text."""
    if isinstance(value, float):
        return "" if math.isnan(value) else float_text(value, float_format)
    if value is None:
        return ""
    return str(value)


class RowWriter:
    """Writes a header, then one row per record (an object with the columns as attributes)."""

    def __init__(self, fh: TextIO, columns: Sequence[str], float_format: str = FLOAT_FORMAT):
        self.columns = list(columns)
        self.float_format = float_format
        self._float = float_formatter(float_format)
        self._w = csv.writer(fh, lineterminator="\n")
        self._w.writerow(self.columns)
        self._values: Any = attrgetter(*self.columns) if len(self.columns) > 1 else \
            (lambda obj: tuple(getattr(obj, c) for c in self.columns))

    def record(self, obj: Any) -> None:
        f = self._float
        # plain floats, strings, booleans and integers inline (a long run writes millions
        # of rows); the rest as cell_text has them
        self._w.writerow([(f(v) if v == v else "") if type(v) is float
                          else v if type(v) is str
                          else str(v) if type(v) is bool or type(v) is int
                          else cell_text(v, self.float_format)
                          for v in self._values(obj)])
