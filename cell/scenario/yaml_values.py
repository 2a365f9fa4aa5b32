"""The values of one YAML document, from PyYAML's parsing events (:mod:`cell.scenario.yamlio`
reads the file, and says why this way).

Two passes over the events: :class:`Walk` keeps the bounds as they come (:data:`MAX_DEPTH`
levels, :data:`MAX_NODES` values, an alias counting the values and levels of what it names, so
an alias bomb is refused in microseconds and a deep nest before the parser reads further), one
document, anchors defined once and before use; it knows each node's key for the message.
:class:`Builder` makes the values by the YAML 1.2 core schema's table (:func:`convert`), a
fresh copy at each use of an alias, and checks the tags and the keys (names, each once, no
merge key).  Each problem is one :class:`~cell.plumbing.errors.ScenarioError` line through
:class:`Source`.
"""

from __future__ import annotations

import copy
import math
import re
from collections.abc import Hashable, Iterable
from dataclasses import dataclass, field
from typing import Any, NoReturn

import yaml

from cell.plumbing.errors import ScenarioError
from cell.plumbing.errors import one_line as _oneline

MAX_DEPTH = 32  #: deepest nesting of lists and mappings
MAX_NODES = 10_000  #: most values in a document, each alias use counted again (baseline.yaml: 188)
MAX_INT_DIGITS = 40  #: most digits in an integer (a 128-bit seed has 39)

_TOO_MANY = f"more than {MAX_NODES:,} values (each use of an alias counts)"
_TOO_DEEP = f"nested deeper than {MAX_DEPTH} levels"
_TAG = "tag:yaml.org,2002:"
_NULL, _BOOL, _INT, _FLOAT, _STR, _SEQ, _MAP = (_TAG + t for t in "null bool int float str seq map".split())
_NULL_RE = re.compile(r"(?:~|null|Null|NULL|)\Z")
_BOOL_RE = re.compile(r"(?:true|True|TRUE|false|False|FALSE)\Z")
_INT_RE = re.compile(r"(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)\Z")
_FLOAT_RE = re.compile(r"(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
                       r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))\Z")
#: The core schema's implicit types, tried in this order on a plain scalar (YAML 1.2, §10.3.2).
_IMPLICIT = ((_NULL, _NULL_RE), (_BOOL, _BOOL_RE), (_INT, _INT_RE), (_FLOAT, _FLOAT_RE))
_SPECIAL = {".inf": math.inf, "+.inf": math.inf, "-.inf": -math.inf, ".nan": math.nan}
KeyPath = list[str | int | None]  # mapping keys and list indices; None: the root, a key being read
#: PyYAML's parser: libyaml's when PyYAML was built with it (30 times faster than its Python one)
LOADER: Any = yaml.CSafeLoader if yaml.__with_libyaml__ else yaml.SafeLoader


_KINDS = {cls: cls.__name__.removesuffix("Event") for cls in vars(yaml.events).values()
          if isinstance(cls, type) and issubclass(cls, yaml.events.Event)}


def _kind(event: Any) -> str:
    """``Scalar``, ``Alias``, ``SequenceStart``, ``MappingEnd``, ``DocumentStart`` ...: the
    event's class name less ``Event`` (:mod:`yaml.events`, whichever parser made it)."""
    return _KINDS[type(event)]


def _tag_of(event: Any) -> str:
    """A node's tag: the one written, else the one the core schema resolves (a plain scalar by
    :data:`_IMPLICIT`, any other scalar str, a collection seq or map)."""
    if event.tag is not None and event.tag != "!":
        return str(event.tag)
    kind = _kind(event)
    if kind != "Scalar":
        return _SEQ if kind == "SequenceStart" else _MAP
    implicit = event.implicit[0] and next((t for t, regex in _IMPLICIT if regex.match(event.value)), None)
    return implicit or _STR


@dataclass
class _Open:
    """A collection being read: its key in its parent, what the bounds need, its key/value state."""

    event: Any
    index: str | int | None
    before: int = 0  # values counted before it
    outer_deepest: int = 0
    children: int = 0  # nodes read in it (a mapping's keys and values alternate)
    key: Any = None  # a mapping's last key: its first event
    unspaced: bool = False  # a flow mapping with a key like ``loc:3`` and no value (first pass)
    out: Any = None  # the value built (second pass)
    part: Any = None  # a mapping's last key built (second pass)
    lines: dict[Any, int] = field(default_factory=dict)  # a mapping's keys and their lines

    @property
    def wants_value(self) -> bool:
        return self.children % 2 == 1 and _kind(self.event) == "MappingStart"


def _dotted(path: Iterable[str | int | None], limit: int = 80) -> str:
    """``run.seed``, ``robot.motors.steps_per_rad[2]``; a very long one keeps its end."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part is not None:
            out += ("." if out else "") + _oneline(part, 40)
    return out if len(out) <= limit else "…" + out[1 - limit:]


class Source:
    """A text being read: its name, and how to name a place in it.  ``echo``: whether errors
    may quote its lines (not for a file that does not look like YAML: ``/etc/passwd``)."""

    def __init__(self, name: str, text: str, inline: bool = False, echo: bool = True):
        self.name, self.text, self.inline, self.echo = _oneline(name), text, inline, echo
        self.lines = text.splitlines() or [""]

    def line_text(self, line: int) -> str:
        """The source line ``line`` (0-based), or the last non-blank one before it."""
        line = min(line, len(self.lines) - 1)
        while line > 0 and not self.lines[line].strip():
            line -= 1
        return _oneline(self.lines[line].strip(), 60) if self.echo else f"<line {line + 1}>"

    def char(self, line: int, column: int) -> str:
        """The character at a place (0-based), or "" past a line's end."""
        text = self.lines[line] if line < len(self.lines) else ""
        return text[column:column + 1]

    def where(self, line: int, column: int) -> str:
        end = line >= len(self.lines) or (line == len(self.lines) - 1 and column >= len(self.lines[line]))
        return "the end" if end else f"column {column + 1}" if self.inline and len(self.lines) == 1 \
            else f"line {line + 1}, column {column + 1}"

    def fail(self, path: KeyPath, value: object, why: str, default_key: str = "(file)") -> NoReturn:
        raise ScenarioError(self.name, _dotted(path) or default_key, value, _oneline(why, 220))

    def fail_at(self, path: KeyPath, mark: Any, why: str, key: str = "(top level)") -> NoReturn:
        self.fail(path, self.line_text(mark.line), f"{why} at {self.where(mark.line, mark.column)}", key)


class Walk:
    """The first pass: the parser's events as they come, the bounds kept (an alias counts the
    values and levels of what it names, so a bomb is refused in microseconds and a deep nest
    before the parser reads further), one document, known anchors; the node events are kept
    for :class:`Builder`.  :meth:`where` names the node being read, as the messages do."""

    def __init__(self, src: Source):
        self.src = src
        self.open: list[_Open] = []
        self.nodes = self.depth = self.deepest = 0
        self.anchors: dict[str, tuple[Any, tuple[int, int] | None]] = {}  # -> (its node, (values, levels))
        self.kept: list[Any] = []
        self.unspaced: dict[int, tuple[Any, Any]] = {}  # id -> (start, end) of a ``{loc:3}``
        self.stage = 0  # 0: before the document, 1: reading its root, 2: after it

    def run(self) -> list[Any]:
        events = iter(yaml.parse(self.src.text, Loader=LOADER))  # only PyYAML's parser is used
        while True:
            try:
                event = next(events, None)
            except yaml.MarkedYAMLError as exc:
                syntax_error(self.src, self.where(), exc.problem_mark or exc.context_mark,
                             exc.problem or "", exc.context or "", exc.context_mark)
            except yaml.YAMLError as exc:  # pragma: no cover - the parser marks its errors
                self.src.fail(self.where(), "", f"invalid YAML: {exc}", "(syntax)")
            if event is None:
                return self.kept
            self.take(event)

    def take(self, event: Any) -> None:
        kind = _kind(event)
        if kind == "DocumentStart":
            if self.stage:
                syntax_error(self.src, self.where(), event.start_mark, "but found another document",
                             "expected a single document in the stream")
            self.stage = 1
        elif kind in ("Scalar", "Alias", "SequenceStart", "MappingStart"):
            self.node(event, kind)
        elif kind in ("SequenceEnd", "MappingEnd"):
            top = self.open.pop()
            self.kept.append(event)
            if top.unspaced:
                self.unspaced[id(top.event)] = top.event, event
            self.close(top.event, top.before, top.outer_deepest, 1)

    def child(self) -> str | int | None:
        """The key of the node that comes next: None for the root or a mapping's key, the key's
        text for its value, the position in a list."""
        if not self.open:
            return None
        top = self.open[-1]
        if _kind(top.event) == "SequenceStart":
            return top.children
        node = self.scalar(top.key) if top.wants_value else None
        return None if node is None else node.value

    def where(self, node: bool = False) -> KeyPath:
        """The key path as the reader stands, with the node just met when ``node``."""
        if not self.open:
            return [None] if self.stage == 1 else []
        top = self.open[-1]
        path: KeyPath = [o.index for o in self.open]
        return path + [self.child()] if node or top.wants_value else path

    def scalar(self, node: Any) -> Any:
        """A scalar event, or the one an alias names; None for anything else."""
        if _kind(node) == "Alias":
            node = self.anchors[node.anchor][0]
        return node if node is not None and _kind(node) == "Scalar" else None

    def node(self, event: Any, kind: str) -> None:
        known = self.anchors.get(event.anchor) if kind == "Alias" else None
        if known is not None:
            if known[1] is None:
                self.src.fail_at(self.where(node=True), event.start_mark,
                                 "an alias refers to a collection that holds it")
            size, levels = known[1]
        else:
            size, levels = 1, int(kind.endswith("Start"))
        too_many = self.nodes + size > MAX_NODES
        if too_many or self.depth + levels > MAX_DEPTH:
            self.src.fail_at(self.where(node=True), event.start_mark, _TOO_MANY if too_many else _TOO_DEEP)
        before, outer_deepest = self.nodes, self.deepest
        self.nodes, self.depth = self.nodes + size, self.depth + levels
        self.deepest = self.depth
        if kind == "Alias" and known is None:
            syntax_error(self.src, self.where(node=True), event.start_mark,
                         f"found undefined alias {event.anchor!r}")
        if kind != "Alias" and event.anchor is not None:
            if event.anchor in self.anchors:
                syntax_error(self.src, self.where(node=True), event.start_mark, "second occurrence",
                             f"found duplicate anchor {event.anchor!r}; first occurrence",
                             self.anchors[event.anchor][0].start_mark)
            self.anchors[event.anchor] = event, None
        self.kept.append(event)
        if levels and kind != "Alias":
            self.open.append(_Open(event, self.child(), before, outer_deepest))
        else:
            self.close(event, before, outer_deepest, levels)

    def close(self, event: Any, before: int, outer_deepest: int, levels: int) -> None:
        """A node read whole: its size kept for its aliases, and its place in its parent."""
        self.depth -= levels
        if _kind(event) != "Alias" and event.anchor is not None:
            self.anchors[event.anchor] = event, (self.nodes - before, self.deepest - self.depth)
        self.deepest = max(outer_deepest, self.deepest)
        if not self.open:
            self.stage = 2
            return
        top = self.open[-1]
        if top.wants_value:
            top.unspaced = top.unspaced or bool(top.event.flow_style) and _unspaced(
                self.scalar(top.key), self.scalar(event))
        elif _kind(top.event) == "MappingStart":
            top.key = event
        top.children += 1


def _unspaced(key: Any, value: Any) -> bool:
    """``loc:3`` read as a key without a value: a plain key with a colon, a plain empty null."""
    return key is not None and value is not None and not key.style and ":" in key.value \
        and _tag_of(value) == _NULL and not value.value and not value.style


class Builder:
    """The second pass: Python values from the kept events, a fresh copy at each use of an
    alias; the core schema's types, the tags, the keys (names, once each) checked."""

    def __init__(self, src: Source, unspaced: dict[int, tuple[Any, Any]]):
        self.src, self.unspaced = src, unspaced
        self.open: list[_Open] = []
        self.anchored: dict[str, tuple[Any, Any]] = {}  # name -> (its first event, its value)
        self.root: Any = None

    def build(self, events: list[Any]) -> Any:
        for event in events:
            kind = _kind(event)
            if kind == "Scalar":
                self.place(self.scalar(event), event)
            elif kind == "Alias":
                first, value = self.anchored[event.anchor]
                self.place(copy.deepcopy(value), first, alias=True)
            elif kind.endswith("Start"):
                self.start(event, kind)
            else:
                top = self.open.pop()
                self.place(top.out, top.event)
        return self.root

    def path(self) -> KeyPath:
        """The key path of the node being built."""
        path: KeyPath = []
        for o in self.open:
            if isinstance(o.out, list):
                path.append(len(o.out))
            elif o.wants_value:
                path.append(o.part)
        return path

    def scalar(self, event: Any) -> Any:
        tag = _tag_of(event)
        if tag in (_STR, _NULL, _BOOL, _INT, _FLOAT):
            try:
                return convert(tag, event.value)
            except ValueError as exc:
                line = event.start_mark.line + 1
                self.src.fail(self.path(), _oneline(event.value, 60), f"{exc} (line {line})")
        self.refuse_tag(event, tag)

    def refuse_tag(self, event: Any, tag: str) -> NoReturn:
        tag = _oneline(tag.replace(_TAG, "!!"), 40)
        self.src.fail_at(self.path(), event.start_mark,
                         f"tag {tag} is not supported: only plain values, lists and mappings")

    def start(self, event: Any, kind: str) -> None:
        tag = _tag_of(event)
        if tag != (_SEQ if kind == "SequenceStart" else _MAP):
            self.refuse_tag(event, tag)
        if id(event) in self.unspaced:
            self.refuse_unspaced(*self.unspaced[id(event)])
        self.open.append(_Open(event, None, out=[] if kind == "SequenceStart" else {}))

    def place(self, value: Any, first: Any, alias: bool = False) -> None:
        """``value`` (from the node whose first event is ``first``) where it goes."""
        if not alias and first.anchor is not None:
            self.anchored[first.anchor] = first, value
        if not self.open:
            self.root = value
            return
        top = self.open[-1]
        if isinstance(top.out, list):
            top.out.append(value)
        elif top.wants_value:
            top.out[top.part] = value
        else:
            top.part, top.key = self.key(top, value, first), first
        top.children += 1

    def key(self, mapping: _Open, key: Any, node: Any) -> str:
        """``key`` checked: a name, not ``<<``, not given before in ``mapping``."""
        path = self.path()
        if not isinstance(key, Hashable) or isinstance(key, list):
            self.src.fail_at(path, node.start_mark, "a key must be a plain value, not a list")
        if not isinstance(key, str):  # every key of these files is a name
            kind = "null" if key is None else "a boolean" if isinstance(key, bool) else "a number"
            self.src.fail_at(path + [node.value], node.start_mark,
                             f"a key must be a name, not {kind} ({_oneline(node.value or '~', 40)})")
        line = node.start_mark.line + 1
        if key == "<<" and not node.style:
            self.src.fail_at(path + [key], node.start_mark,
                             "merge keys (<<) are YAML 1.1, not supported; write the keys out")
        if key in mapping.out:
            self.src.fail(path + [key], self.src.line_text(line - 1),
                          f"duplicate key: first on line {mapping.lines[key]}, again on line {line}")
        mapping.lines[key] = line
        return key

    def refuse_unspaced(self, start: Any, end: Any) -> NoReturn:
        """``{loc:3,scale:2}`` is YAML for the keys ``loc:3`` and ``scale:2`` without values:
        refused, showing it with the spaces meant."""
        text = self.src.text[start.start_mark.index:end.end_mark.index]
        spaced = re.sub(r"([:,])(?=[^\s,:}\]])", r"\1 ", text)
        self.src.fail(self.path(), _oneline(text, 60),
                      f"YAML needs a space after ':' ({_oneline(spaced, 80)})", "(syntax)")


def convert(tag: str, text: str) -> Any:
    """A scalar resolved (or tagged) as str, null, bool, int or float; ValueError if it is not one."""
    if tag == _STR:
        return text
    if tag == _NULL and _NULL_RE.match(text):
        return None
    if tag == _BOOL and _BOOL_RE.match(text):
        return text.lower() == "true"
    if tag in (_INT, _FLOAT) and _INT_RE.match(text):
        digits = text.lstrip("+-").removeprefix("0o").removeprefix("0x")
        if len(digits) > MAX_INT_DIGITS:
            raise ValueError(f"an integer of {len(digits):,} digits; at most {MAX_INT_DIGITS} are allowed")
        base = {"0o": 8, "0x": 16}.get(text[:2], 10)
        number = int(text[2:] if base != 10 else text, base)
        return number if tag == _INT else float(number)
    if tag == _FLOAT and _FLOAT_RE.match(text):
        return _SPECIAL[text.lower()] if text.lower() in _SPECIAL else float(text)
    raise ValueError({_NULL: "not null", _BOOL: "not a boolean: write true or false",
                      _INT: "not an integer"}.get(tag, "not a number"))


def syntax_error(src: Source, path: KeyPath, mark: Any, problem: str, context: str = "",
                 cmark: Any = None) -> NoReturn:
    """Invalid YAML (the parser's ``problem`` at ``mark``, while reading ``context`` from
    ``cmark``), said on one line."""
    if mark is None:  # pragma: no cover - the parser marks every syntax error
        src.fail(path, "", f"invalid YAML: {problem or context}", "(syntax)")
    if "nesting depth" in problem:  # libyaml's own bound (1000 levels), met while looking ahead
        src.fail_at(path, mark, _TOO_DEEP)
    if src.char(mark.line, mark.column) == "\t":  # "cannot start any token", "violates indentation"
        problem, context = "a tab: YAML indents with spaces only", ""
    if problem.startswith("but "):
        problem = f"{context}, {problem}"
    elif context and cmark and (cmark.line, cmark.column) != (mark.line, mark.column):
        problem += f" ({context} from {src.where(cmark.line, cmark.column)})"
    if problem.startswith("mapping values are not allowed") and mark.column > 1024:
        problem += " (a key without quotes may have at most 1024 characters)"
    where = src.where(mark.line, mark.column)
    src.fail(path, src.line_text(mark.line), f"invalid YAML at {where}: {problem or context}", "(syntax)")
