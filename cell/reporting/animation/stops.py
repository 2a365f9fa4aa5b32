"""A frame's stopped equipment (``failures:``, ``wear:``): marked, with its repair clock.

The robot stopped is drawn in red with what stopped it and when it is back; a stopped belt
says so beside its speed; a failed sensor under the robot's line.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

#: How a stop's cause reads on a frame.
STOP_WORDS = {"failure": "breakdown", "wear": "worn motor", "maintenance": "maintenance"}
DOWN_COLOUR = "#c0392b"


def duration(seconds: float) -> str:
    """A repair clock: h:mm:ss (or m:ss under an hour), rounded up to the second."""
    whole = max(0, math.ceil(seconds))
    hours, rest = divmod(whole, 3600)
    minutes, secs = divmod(rest, 60)
    return f"{hours}:{minutes:02d}:{secs:02d}" if hours else f"{minutes}:{secs:02d}"


def stop_lines(down: Mapping[str, tuple[str, float]]) -> dict[str, str]:
    """What a frame says of each stopped piece of equipment (name -> its words)."""
    out = {}
    for name, (cause, left) in down.items():
        what = STOP_WORDS.get(cause, cause)
        if name == "robot":
            out[name] = f"robot DOWN ({what}): back in {duration(left)}"
        elif name == "sensor":
            out[name] = f"sensor down: back in {duration(left)}"
        else:
            out[name] = f"STOPPED ({what}), back in {duration(left)}"
    return out


def mark_stops(down: Mapping[str, tuple[str, float]], texts: Mapping[str, Any],
               arm: Iterable[Any]) -> None:
    """Mark the stopped equipment on a frame whose texts and arm are already drawn."""
    texts["belts"].set_color(DOWN_COLOUR if "input_belt" in down or "output_belt" in down
                             else "black")
    if not down:
        return
    words = stop_lines(down)
    belts = texts["belts"].get_text().split("\n")
    for k, name in enumerate(("input_belt", "output_belt")):
        if name in words and k < len(belts):
            belts[k] += "  " + words[name]
    texts["belts"].set_text("\n".join(belts))
    if "robot" in words:
        texts["robot"].set_text(words["robot"])
        texts["robot"].set_color(DOWN_COLOUR)
        for line in arm:
            line.set_color(DOWN_COLOUR)
    if "sensor" in words:
        texts["robot"].set_text(texts["robot"].get_text() + "\n" + words["sensor"])
