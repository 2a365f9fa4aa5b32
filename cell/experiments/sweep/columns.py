"""The grid's columns in ``replications.csv`` and the reports: tidy, one value per cell.

Each varied key becomes one column, or, when its values are mappings (a whole
``arrivals.params``, a section), one column per leaf the sweep file gives
(``arrivals.params.loc``); list values one per item (``key[0]``).  Keys whose grid
values are named (``key: {name: value, ...}``) get a column ``KEY.name`` first.
Values are the point's own, as numbers (strings, booleans) -- never Python reprs.

A point that does not vary a key holds its scenario's value there, so a plain
``groupby`` keeps every row.  Where the scenario leaves a setting empty and the
run reports a summary column of the same name, the run's value is used: for
``controller.ideal_cycle_s`` the cycle the policy actually plans for
(``ideal_cycle_s``; the nominal cycle for the adaptive policy).  A file the point
names (:data:`cell.scenario.schema.PATH_KEYS`) is shown as the sweep file wrote it, not as
the path it is read from.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from cell.experiments.sweep.spec import Point, Sweep
from cell.scenario.schema import PATH_KEYS

NAME_SUFFIX = ".name"
_PATH_COLUMNS = frozenset(".".join(k) for k in PATH_KEYS)
_TOKEN = re.compile(r"\[(\d+)\]|([^.\[\]]+)")


def flatten(prefix: str, value: Any) -> dict[str, Any]:
    """Leaf columns of a value: mappings by ``.key``, lists by ``[i]``, anything else as is."""
    if hasattr(value, "model_dump"):
        value = value.model_dump()
    if isinstance(value, Mapping):
        out: dict[str, Any] = {}
        for k, v in value.items():
            out.update(flatten(f"{prefix}.{k}", v))
        return out
    if isinstance(value, (list, tuple)):
        out = {}
        for i, v in enumerate(value):
            out.update(flatten(f"{prefix}[{i}]", v))
        return out
    return {prefix: value}


def lookup(doc: Any, column: str) -> Any:
    """The value at a leaf column's path in plain data (None where there is none)."""
    for index, name in _TOKEN.findall(column):
        if index and isinstance(doc, (list, tuple)) and int(index) < len(doc):
            doc = doc[int(index)]
        elif name and isinstance(doc, Mapping) and name in doc:
            doc = doc[name]
        else:
            return None
    return doc


@dataclass(frozen=True)
class Column:
    """One grid column: its name, the varied key it comes from, and whether it holds
    the name of the key's value rather than a value."""

    name: str
    key: str
    is_name: bool = False

    @property
    def leaf(self) -> str:
        """The last part of the path (``loc`` of ``arrivals.params.loc``)."""
        return _TOKEN.findall(self.name)[-1][1] or self.name


def grid_columns(sweep: Sweep) -> list[Column]:
    """The sweep's grid columns, in the order of its keys."""
    out: list[Column] = []
    for key in sweep.keys:
        if any(p.name_of(key) for p in sweep.points):
            out.append(Column(key + NAME_SUFFIX, key, is_name=True))
        leaves: dict[str, None] = {}
        for p in sweep.points:
            values = dict(p.values)
            if key in values:
                leaves.update(dict.fromkeys(flatten(key, values[key])))
        out += [Column(leaf, key) for leaf in leaves]
    return out


def point_values(columns: Sequence[Column], point: Point,
                 summary: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """A point's value in each grid column (see the module's docstring)."""
    given = dict(point.values)
    doc = point.scenario.to_dict()
    out: dict[str, Any] = {}
    for c in columns:
        if c.is_name:
            out[c.name] = point.name_of(c.key) or ""
            continue
        value = lookup(doc, c.name)  # the scenario's value, as validated
        if c.name in _PATH_COLUMNS and c.key in given:  # as written, not resolved
            value = flatten(c.key, given[c.key]).get(c.name, value)
        if value is None and c.key in given:  # a key that is not a scenario setting
            value = flatten(c.key, given[c.key]).get(c.name)
        if value is None and summary is not None and c.leaf in summary:
            value = summary[c.leaf]
        out[c.name] = value
    return out
