"""One exception tree, rooted at :class:`CellError`.

The command line turns any ``CellError`` into one line on stderr and exit code 2.
"""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Iterable, Sized


class CellError(Exception):
    """Base of every error the package raises on purpose."""


class ScenarioError(CellError, ValueError):
    """A scenario (or sweep) file has a bad key or value.

    The message always names the file, the dotted key and the offending value.
    """

    def __init__(self, file: object, key: str, value: object, why: str):
        if isinstance(value, tuple):  # a setting held as a tuple was written as a YAML list
            value = list(value)
        self.file, self.key, self.value, self.why = str(file), key, value, why
        super().__init__(f"{_line(self.file)}: {_line(key)} = {short(value)}: {_line(why, 300)}")

    def given_with_set(self, keys: Iterable[str]) -> ScenarioError:
        """This error with its file marked ``(--set)`` when its key is one of the dotted
        ``keys`` given with ``--set`` (or lies within or around one: ``run`` holds ``run.parts``,
        ``robot.motors.steps_per_rad`` its item ``robot.motors.steps_per_rad[2]``): the value
        is the command line's, not the file's.  Itself otherwise."""
        key = self.key
        if self.file.endswith(" (--set)") or not any(
                key == k or key.startswith((k + ".", k + "[")) or k.startswith(key + ".") for k in keys):
            return self
        return ScenarioError(f"{self.file} (--set)", key, self.value, self.why)


class UnreachableError(CellError, ValueError):
    """A pose is out of the arm's reach or outside a joint's range.

    ``index`` is the position of the first bad pose in the batch given to the
    inverse kinematics; ``joint`` the joint (0-4) outside its range, or None when
    the pose is out of reach altogether.
    """

    def __init__(self, message: str, index: int = 0, joint: int | None = None):
        self.index, self.joint = index, joint
        super().__init__(message)


class InfeasibleError(CellError, ValueError):
    """A requested timing asks more than the motors can give."""


class NoMotionError(CellError):
    """No admissible motion along a path under the given bounds (the planner)."""


# --------------------------------------------------------------------------- messages
def one_line(text: str, limit: int = 200) -> str:
    """``text`` without line breaks, cut to ``limit`` characters."""
    text = " ".join(str(text).splitlines())
    return text if len(text) <= limit else text[:limit - 1] + "…"


_line = one_line


def shown_path(path: object, limit: int = 160) -> str:
    """A path as a message shows it: printable (else its repr), a very long one cut in the middle."""
    text = os.fsdecode(path) if isinstance(path, (str, bytes, os.PathLike)) else str(path)
    if not (text.isprintable() and text):
        text = repr(text)
    if len(text) <= limit:
        return text
    keep = (limit - 1) // 2
    return f"{text[:keep]}…{text[-(limit - 1 - keep):]}"


def short(value: object, limit: int = 80) -> str:
    """``repr(value)`` cut near ``limit`` characters, with the size of what was cut.

    ``'aaaa…' (39,000,000 characters)``, ``[1, 2, …] (20,000 items)``.  The cost depends on
    ``limit``, not on the size of ``value``, except for types other than str, bytes, numbers,
    lists, tuples, dicts and sets, whose own ``repr`` is used.
    """
    text, complete = _short(value, max(limit, 8))
    if complete:
        return text
    if isinstance(value, int):
        return f"{text} (about {_digits(value):,} digits)"
    if not isinstance(value, Sized):
        return f"{text} ({type(value).__name__})"
    unit = "characters" if isinstance(value, str) else "bytes" if isinstance(value, (bytes, bytearray)) \
        else "items" if len(value) != 1 else "item"
    return f"{text} ({len(value):,} {unit})"


def _digits(value: int) -> int:
    return int(abs(value).bit_length() * math.log10(2)) + 1


def _short(value: object, budget: int) -> tuple[str, bool]:
    """``(text, complete)``: the repr of ``value`` if it fits in ``budget``, else a cut one."""
    if isinstance(value, (str, bytes, bytearray)):
        head = repr(value[:budget])
        if len(value) <= budget and len(head) <= budget:
            return head, True
        return head[:max(budget - 2, 2)] + "…" + head[-1], False
    if isinstance(value, int) and not isinstance(value, bool) and _digits(value) > 1000:
        return ("-" if value < 0 else "") + "<integer>", False
    if not (isinstance(value, (list, tuple, dict)) or isinstance(value, (set, frozenset)) and value):
        try:
            text = _line(repr(value), 10**9)
        except Exception:  # noqa: BLE001 - a failing repr still gives a name
            text = f"<{type(value).__name__}>"
        return (text, True) if len(text) <= budget else (text[:max(budget - 1, 1)] + "…", False)
    pairs, text, shown, complete = isinstance(value, dict), "", 0, True
    for item in itertools.islice(value.items() if isinstance(value, dict) else value, budget):
        room = budget - len(text) - 6  # keep room for ", …]"
        if room < 2:
            break
        part, complete = _short(item[0] if pairs else item, room)
        if pairs and complete:
            tail, complete = _short(item[1], max(room - len(part) - 2, 2))
            part += ": " + tail
        text, shown = text + (", " if shown else "") + part, shown + 1
        if not complete:
            break
    if shown < len(value):
        text, complete = text + (", …" if shown else "…"), False
    brackets = "[]" if isinstance(value, list) else "()" if isinstance(value, tuple) else "{}"
    comma = "," if isinstance(value, tuple) and len(value) == 1 and complete else ""
    return brackets[0] + text + comma + brackets[1], complete
