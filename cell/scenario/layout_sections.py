"""The ``buffer:`` and ``stations:`` sections of a scenario file: an accumulating buffer before
B, and more stations on the same input belt or in series (docs/layout.md).  Split from
:mod:`cell.scenario.sections`; :mod:`cell.scenario.schema` puts them together with the rest.

A station's sections (``controller``, ``robot``, ``path``, ``sensor``, ``failures``, ``buffer``,
``cell``, ``belts``, ``mintime``) are overrides of the scenario's own, which are the first
station's: each is merged into the scenario's and the whole validated as a scenario, so a bad
value is named by its full key, ``stations.catcher.controller.ideal_cycle_s``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

from pydantic import Field

from cell.scenario.fields import Section
from cell.scenario.sections import MAX_LENGTH_IN, finite

#: The sections a station may override (the scenario's own are the first station's).
STATION_SECTIONS = ("cell", "path", "robot", "belts", "controller", "sensor", "failures",
                    "buffer", "mintime")
#: The most stations a line may have (a bound on slips, as the other bounds).
MAX_STATIONS = 20


class BufferSettings(Section):
    """An accumulating section ending at a gate at B (docs/layout.md)."""

    places: int = Field(0, strict=True, ge=0, le=10_000)
    """Parts that can wait at the gate and behind it (the part in the robot's hand not
    counted); 0: no buffer, the thesis's cell."""
    pitch_in: float | None = finite(None, gt=0.0, le=MAX_LENGTH_IN)
    """Centre-to-centre distance of waiting parts (in), at least the part's size.  Empty: the
    part's size (parts touching)."""
    when_full: Literal["ride_off", "hold_feeder"] = "ride_off"
    """What happens to a part that finds every place taken: ``ride_off``, it rides on past the
    buffer and is lost (or caught downstream); ``hold_feeder``, it stands behind the buffer and
    the line before it holds (nothing is lost)."""


class StationSettings(Section):
    """One more station: a robot with its controller and its own output belt (docs/layout.md)."""

    name: str = Field(..., strict=True, min_length=1, max_length=40, pattern=r"^[A-Za-z0-9_-]+$")
    """How the station is named in ``--set``, ``stations.csv`` and ``parts.csv``."""
    placement: Literal["downstream", "series"]
    """``downstream``: on the same input line, taking the parts the station before it lets
    ride past its F; ``series``: fed by the output belt of the last station before it that is
    not ``downstream`` (the scenario's own cell, or a series station)."""
    offset_in: float | None = finite(None, le=MAX_LENGTH_IN)
    """``downstream``: how far past the station before it's F this station's B lies (in)."""
    transfer_in: float | None = finite(None, le=MAX_LENGTH_IN)
    """``series``: the length from the feeding station's touch-down point to this station's B
    (in), carried at this station's input belt speed."""
    cell: dict[str, Any] | None = None
    """Overrides of the scenario's ``cell:`` section for this station."""
    path: dict[str, Any] | None = None
    """Overrides of ``path:``."""
    robot: dict[str, Any] | None = None
    """Overrides of ``robot:``."""
    belts: dict[str, Any] | None = None
    """Overrides of ``belts:`` (``input_length_in`` is the offset or transfer)."""
    controller: dict[str, Any] | None = None
    """Overrides of ``controller:`` (its own policy)."""
    sensor: dict[str, Any] | None = None
    """Overrides of ``sensor:``."""
    failures: dict[str, Any] | None = None
    """Overrides of ``failures:`` (its own equipment fails on its own clocks)."""
    buffer: dict[str, Any] | None = None
    """Overrides of ``buffer:`` (``{places: 0}``: none at this station)."""
    mintime: dict[str, Any] | None = None
    """Overrides of ``mintime:``."""


def station_raw(base: Mapping[str, Any], station: StationSettings,
                merge: Any, is_section: Any) -> dict[str, Any]:
    """The station's scenario as plain data: the scenario's (without ``stations``) with the
    station's sections merged in and its input window's length, the offset or the transfer."""
    raw = {k: v for k, v in base.items() if k != "stations"}
    for name in STATION_SECTIONS:
        given = getattr(station, name)
        if given is not None:
            raw = merge(raw, {name: given}, (), is_section)
    length = station.offset_in if station.placement == "downstream" else station.transfer_in
    raw["belts"] = {**raw.get("belts", {}), "input_length_in": length}
    raw["name"] = f"{raw.get('name', '')}/{station.name}"
    return raw
