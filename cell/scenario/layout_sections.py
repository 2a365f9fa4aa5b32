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

from cell.plumbing.errors import ScenarioError
from cell.scenario.fields import Section
from cell.scenario.sections import MAX_LENGTH_IN, finite

#: The sections a station may override (the scenario's own are the first station's).
STATION_SECTIONS = ("cell", "path", "robot", "belts", "controller", "sensor", "failures",
                    "buffer", "mintime")
#: The scenario's own cell's name in stations.csv and parts.csv (the first station).
FIRST_STATION = "first"
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


def station_raw(base: Mapping[str, Any], station: StationSettings, merge: Any) -> dict[str, Any]:
    """The station's scenario as plain data: the scenario's (without ``stations``) with the
    station's sections merged in and its input window's length, the offset or the transfer."""
    raw = {k: v for k, v in base.items() if k != "stations"}
    for name in STATION_SECTIONS:
        given = getattr(station, name)
        if given is not None:
            raw = merge(raw, {name: given})
    length = station.offset_in if station.placement == "downstream" else station.transfer_in
    raw["belts"] = {**raw.get("belts", {}), "input_length_in": length}
    raw["name"] = f"{raw.get('name', '')}/{station.name}"
    return raw


def named_station(exc: ScenarioError, raw: Any) -> ScenarioError:
    """A station's key by the station's name (``stations.catcher.offset_in``) rather than by
    its place in the list (``stations[1].offset_in``), when it has one."""
    key = exc.key
    if not key.startswith("stations["):
        return exc
    index, _, rest = key[len("stations["):].partition("]")
    try:
        name = raw["stations"][int(index)]["name"]
    except (KeyError, IndexError, TypeError, ValueError):
        return exc
    if not isinstance(name, str) or not name:
        return exc
    return ScenarioError(exc.file, f"stations.{name}{rest}", exc.value, exc.why)


def check_layout(s: Any, raw: Mapping[str, Any], file: object, validate: Any, merge: Any) -> None:
    """The buffer's pitch against the part; each station placed where it can work, and its
    own scenario (the scenario's sections with its overrides) valid, its keys named in full."""
    b = s.buffer
    if b is not None and b.pitch_in is not None and b.pitch_in < s.part.size_in:
        raise ScenarioError(file, "buffer.pitch_in", b.pitch_in, f"shorter than the part "
                            f"({s.part.size_in:g} in, part.size_in): waiting parts would overlap")
    if not s.stations:
        return
    seen: set[str] = set()
    base = {k: v for k, v in raw.items() if k != "stations"}
    for st in s.stations:
        key = f"stations.{st.name}"
        if st.name in seen or st.name == FIRST_STATION:
            raise ScenarioError(file, f"{key}.name", st.name, "two stations have this name"
                                if st.name in seen else "names the scenario's own cell (the "
                                "first station in stations.csv): choose another")
        seen.add(st.name)
        own, other = ("offset_in", "transfer_in") if st.placement == "downstream" else \
            ("transfer_in", "offset_in")
        if getattr(st, other) is not None:
            raise ScenarioError(file, f"{key}.{other}", getattr(st, other),
                                "not for a " + st.placement + " station")
        length = getattr(st, own)
        if length is None:
            raise ScenarioError(file, f"{key}.{own}", None, f"a {st.placement} station needs it")
        if st.placement == "downstream":  # no closer than the open hand's span: the hand at
            clear = s.robot.hand.open_in  # F and the one at B could touch (docs/layout.md)
            if length < 0:
                raise ScenarioError(file, f"{key}.offset_in", length, "places the station "
                                    "before the F of the station it follows: it must lie past it")
            if length < clear:
                raise ScenarioError(file, f"{key}.offset_in", length, f"closer than the open "
                                    f"hand's span ({clear:g} in, robot.hand.open_in): the two "
                                    "arms could collide")
        elif not length > 0:
            raise ScenarioError(file, f"{key}.transfer_in", length, "a transfer must have a "
                                "length: the station needs a drop point before its B")
        try:
            own_s = validate(station_raw(base, st, merge))
        except ScenarioError as exc:
            inner = own if exc.key == "belts.input_length_in" else exc.key
            raise ScenarioError(exc.file, f"{key}.{inner}", exc.value, exc.why) from None
        s._stations.append((st, own_s))
