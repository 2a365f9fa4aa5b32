"""Dotted keys: ``--set KEY=VALUE`` and the keys a sweep varies.

A dotted key names one setting (``controller.ideal_cycle_s``) or reaches into a
mapping-valued one (``arrivals.params.scale``).  A mapping given for a *section*
merges into it, so ``--set 'run={seed: 9}'`` keeps ``run.parts``; a mapping given
for a *value* (``arrivals.params``) replaces it whole, since a distribution's
parameters belong together.  Which keys are sections is the schema's business:
callers pass ``is_section``.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from cell.plumbing.errors import CellError, ScenarioError, short

#: Does this dotted path (as a tuple of names) name a section of the schema?
IsSection = Callable[[tuple[str, ...]], bool]


def _never(path: tuple[str, ...]) -> bool:
    return False


def parse_sets(pairs: Sequence[str] | None) -> dict[str, Any]:
    """``--set key=value`` pairs as dotted overrides; values are read as YAML."""
    from cell.scenario.yamlio import parse_value

    out: dict[str, Any] = {}
    for pair in pairs or ():
        key, sep, text = pair.partition("=")
        key = key.strip()
        if not sep or not key:
            raise CellError(f"--set {short(pair)}: expected KEY=VALUE, e.g. run.parts=100")
        out[key] = parse_value(text, origin=f"--set {key}")
    return out


def apply_overrides(raw: Mapping[str, Any], overrides: Mapping[str, Any], file: object,
                    is_section: IsSection = _never) -> dict[str, Any]:
    """A copy of ``raw`` with each dotted key set (sections merged, values replaced); ``raw``
    is left as it was: the mappings on a key's way are copied, the rest shared."""
    out = dict(raw)
    for key, value in overrides.items():
        set_dotted(out, str(key), value, file, is_section)
    return out


def set_dotted(raw: dict[str, Any], key: str, value: Any, file: object,
               is_section: IsSection = _never) -> None:
    parts = tuple(key.split("."))
    if not all(parts):
        raise ScenarioError(file, key, value, "a dotted key has an empty part")
    node = raw
    i = -1
    while i + 1 < len(parts) - 1:
        i += 1
        part = parts[i]
        child = node.get(part)
        if isinstance(child, list) and i + 2 < len(parts):  # a list of named entries
            node, i = _named_entry(node, part, child, parts[i + 1], key, value, file), i + 1
            continue
        if child is None:
            child = node[part] = {}
        elif not isinstance(child, dict):
            where = ".".join(parts[:i + 1])
            raise ScenarioError(file, key, value, f"{where} is {child!r}, not a section "
                                "whose keys can be set")
        else:
            child = node[part] = dict(child)
        node = child
    leaf = parts[-1]
    old = node.get(leaf)
    if isinstance(value, Mapping) and is_section(parts) and isinstance(old, dict):
        node[leaf] = merge(old, value, parts, is_section)
    else:
        node[leaf] = copy.deepcopy(value)


def _named_entry(node: dict[str, Any], part: str, items: list[Any], name: str, key: str,
                 value: Any, file: object) -> dict[str, Any]:
    """The entry of a list of mappings (``stations``) whose ``name`` is ``name``, copied into
    place so that setting its keys leaves the original as it was."""
    items = node[part] = list(items)
    for j, item in enumerate(items):
        if isinstance(item, Mapping) and item.get("name") == name:
            entry = items[j] = dict(item)
            return entry
    names = [str(item.get("name")) for item in items if isinstance(item, Mapping)]
    raise ScenarioError(file, key, value, f"no entry of {part} is named {name} (named: "
                        + ", ".join(names) + ")")


def merge(base: Mapping[str, Any], update: Mapping[str, Any], path: tuple[str, ...] = (),
          is_section: IsSection = _never) -> dict[str, Any]:
    """``update`` merged into ``base``: sections recursively, everything else replaced."""
    out = dict(base)
    for k, v in update.items():
        here = (*path, str(k))
        if v is None and is_section(here) and isinstance(out.get(k), Mapping):
            continue  # an empty section: its defaults stand
        if isinstance(v, Mapping) and is_section(here) and isinstance(out.get(k), Mapping):
            out[k] = merge(out[k], v, here, is_section)
        else:
            out[k] = copy.deepcopy(v)
    return out
