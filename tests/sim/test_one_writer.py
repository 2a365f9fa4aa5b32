"""One writer for each field (issue 20): every slot of a part in flight
(:class:`cell.sim.records.Part`) is assigned in one module of the model, by the process that
owns it, and parts.csv's rows (:class:`cell.sim.records.PartRecord`) cannot be written at all."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from cell.sim.records import PART_COLUMNS, Part, PartRecord

CELL = Path(__file__).resolve().parents[2] / "cell"

#: Each slot's one writer (module, and the process it is part of); ``index``, ``arrival_s``
#: and ``feed_delay_s`` are the feeder's, given as it makes the part (:data:`MAKERS`).
OWNERS = {
    # a buffer's gate (docs/layout.md) sets the instant tracking begins as it lets a part go
    "at_bot_s": {"sim/conveyors.py", "sim/buffer.py"}, "plan": {"sim/controller.py"},
    "buffer_wait_s": {"sim/buffer.py"}, "station": {"sim/line.py"},
    # the robot's process, whether or not anything can stop it (its one cycle)
    "pick_s": {"sim/robot.py"},
    "touchdown_s": {"sim/conveyors.py"}, "spacing_in": {"sim/conveyors.py"},
    "delivery_interval_s": {"sim/conveyors.py"},
}


#: The modules that make a Part.
MAKERS = {"sim/feeder.py"}
#: Objects that are not parts and have a slot's name (the policy's ``plan`` method).
NOT_PARTS = {"self", "policy"}


def _writers() -> tuple[dict[str, set[str]], set[str]]:
    """Every module that assigns one of Part's slots on something other than ``self``
    (Part's own ``__init__`` aside), and every module that makes a Part."""
    found: dict[str, set[str]] = {}
    makers: set[str] = set()
    for path in CELL.rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and \
                    node.func.id == "Part":
                makers.add(path.relative_to(CELL).as_posix())
            targets = node.targets if isinstance(node, ast.Assign) else \
                [node.target] if isinstance(node, (ast.AugAssign, ast.AnnAssign)) else []
            stack = list(targets)
            while stack:
                t = stack.pop()
                if isinstance(t, ast.Tuple):
                    stack.extend(t.elts)
                elif isinstance(t, ast.Attribute) and t.attr in Part.__slots__ and not (
                        isinstance(t.value, ast.Name) and t.value.id in NOT_PARTS):
                    found.setdefault(t.attr, set()).add(path.relative_to(CELL).as_posix())
    return found, makers


def test_each_slot_of_a_part_has_its_one_writer():
    found, makers = _writers()
    assert found == OWNERS
    assert makers == MAKERS


def test_a_row_of_parts_csv_cannot_be_changed_once_made():
    row = PartRecord(**{c: 0.0 for c in PART_COLUMNS})
    with pytest.raises(AttributeError):
        row.picked = True  # type: ignore[misc]
