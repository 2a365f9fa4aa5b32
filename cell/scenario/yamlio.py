"""Reading the YAML that users write: every failure is one short line.

YAML 1.2 core schema, not PyYAML's 1.1: ``21e0``, ``2.25872e1``, ``1e-3``, ``+12.5``, ``.inf``,
``.nan`` are floats; ``12``, ``0o17``, ``0x1F`` integers (``0777`` is decimal 777); ``1:30``,
``1_000``, dates and ``yes``/``no``/``on``/``off`` strings; only ``true``/``false`` (``True``,
``TRUE``) booleans; ``null``, ``~`` or nothing None.  Only plain values, lists and mappings:
other tags (``!!binary``, ``!!python/...``), merge keys (``<<``) and a key given twice in a
mapping (PyYAML keeps the last) are refused.  Bounds: :data:`MAX_BYTES` of UTF-8, -16 or -32
text (BOM optional, as in the spec) without control characters; :data:`MAX_DEPTH` levels;
:data:`MAX_NODES` values, each use of an alias counted as the copy it stands for (this defuses
alias bombs; the values returned are such copies, sharing nothing); :data:`MAX_INT_DIGITS`.

Errors are :class:`~cell.plumbing.errors.ScenarioError`: file, dotted key (``robot.motors.steps_per_rad[2]``),
offending text, reason, on one line.  libyaml scans and parses when PyYAML has it (5-10 times
faster on big inputs), PyYAML's Python code otherwise; the composer, which keeps the bounds, is ours.
"""

from __future__ import annotations

import codecs
import math
import os
import re
import stat
from collections.abc import Callable, Hashable, Iterable
from pathlib import Path
from typing import Any, NoReturn

import yaml
from yaml.composer import Composer
from yaml.events import AliasEvent, MappingStartEvent, SequenceStartEvent
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode
from yaml.parser import Parser
from yaml.reader import Reader
from yaml.resolver import BaseResolver
from yaml.scanner import Scanner

from cell.plumbing.errors import ScenarioError
from cell.plumbing.errors import one_line as _oneline

MAX_BYTES = 1 << 20  #: largest file read (bytes); scenario and sweep files are a few kilobytes
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
_SPECIAL = {".inf": math.inf, "+.inf": math.inf, "-.inf": -math.inf, ".nan": math.nan}
#: What YAML allows in a stream: tab, line breaks and printable characters.
_NOT_PRINTABLE = re.compile("[^\t\n\r\x20-\x7e\x85\xa0-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")

KeyPath = list[str | int | None]  # mapping keys and list indices; None while a key is read


class _Refused(yaml.MarkedYAMLError):
    """Valid YAML, but beyond a bound."""


class _Composer(Composer, BaseResolver):
    """PyYAML's composer with the YAML 1.2 resolver, a key path and the bounds (an alias counts
    the values and levels of what it names: an alias bomb is refused in microseconds)."""

    yaml_implicit_resolvers: dict[Any, Any] = {}
    yaml_path_resolvers: dict[Any, Any] = {}
    peek_event: Callable[[], Any]  # from the parser (PyYAML's or libyaml's)
    dispose: Callable[[], None]

    def __init__(self) -> None:
        Composer.__init__(self)
        BaseResolver.__init__(self)
        self.path: KeyPath = []
        self.depth = self.deepest = self.nodes = 0
        self.sizes: dict[int, tuple[int, int]] = {}  # id(node) -> (values, levels)

    def compose_node(self, parent: Node | None, index: Any) -> Node | None:
        # The path is popped on success only: after an error it still names the place.
        self.path.append(index.value if isinstance(index, ScalarNode) else index if isinstance(index, int)
                         else None)
        event, mark = self.peek_event(), self.peek_event().start_mark
        if isinstance(event, AliasEvent) and event.anchor in self.anchors:
            known = self.sizes.get(id(self.anchors[event.anchor]))
            if known is None:
                raise _Refused(problem="an alias refers to a collection that holds it", problem_mark=mark)
            size, levels = known
        else:
            size, levels = 1, int(isinstance(event, (SequenceStartEvent, MappingStartEvent)))
        too_many = self.nodes + size > MAX_NODES
        if too_many or self.depth + levels > MAX_DEPTH:
            raise _Refused(problem=_TOO_MANY if too_many else _TOO_DEEP, problem_mark=mark)
        before, outer_deepest = self.nodes, self.deepest
        self.nodes, self.depth = self.nodes + size, self.depth + levels
        self.deepest = self.depth
        node = super().compose_node(parent, index)
        self.depth -= levels
        self.sizes[id(node)] = self.nodes - before, self.deepest - self.depth
        self.deepest = max(outer_deepest, self.deepest)
        self.path.pop()
        return node


for _tag, _regex, _first in ((_NULL, _NULL_RE, "~nN"), (_BOOL, _BOOL_RE, "tTfF"),
                             (_INT, _INT_RE, "-+0123456789"), (_FLOAT, _FLOAT_RE, "-+.0123456789")):
    _Composer.add_implicit_resolver(_tag, _regex, list(_first) + [""] * (_tag == _NULL))


class _PyLoader(Reader, Scanner, Parser, _Composer):  # PyYAML's pure-Python reader, scanner, parser
    def __init__(self, text: str):
        Reader.__init__(self, text)
        Scanner.__init__(self)
        Parser.__init__(self)
        _Composer.__init__(self)


_Loader: Callable[[str], _Composer] = _PyLoader
if yaml.__with_libyaml__:
    from yaml._yaml import CParser

    class _CLoader(CParser, _Composer):  # libyaml's scanner and parser
        get_single_node = Composer.get_single_node

        def __init__(self, text: str):
            CParser.__init__(self, text)
            _Composer.__init__(self)

    _Loader = _CLoader


def _dotted(path: Iterable[str | int | None], limit: int = 80) -> str:
    """``run.seed``, ``robot.motors.steps_per_rad[2]``; a very long one keeps its end."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part is not None:
            out += ("." if out else "") + _oneline(part, 40)
    return out if len(out) <= limit else "…" + out[1 - limit:]


class _Source:
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


_BOMS = ((codecs.BOM_UTF32_LE, "utf-32-le"), (codecs.BOM_UTF32_BE, "utf-32-be"), (codecs.BOM_UTF8, "utf-8"),
         (codecs.BOM_UTF16_LE, "utf-16-le"), (codecs.BOM_UTF16_BE, "utf-16-be"))


def _decode(data: bytes, source: str) -> str:
    """Bytes as text: a BOM names the encoding, else the NULs around the first character (YAML §5.2)."""
    encoding, skip = next(((name, len(bom)) for bom, name in _BOMS if data.startswith(bom)), ("utf-8", 0))
    nuls = "".join("0" if b == 0 else "x" for b in data[:4])
    if not skip and len(nuls) >= 2:
        encoding = {"000x": "utf-32-be", "x000": "utf-32-le"}.get(nuls) or \
            {"0x": "utf-16-be", "x0": "utf-16-le"}.get(nuls[:2], "utf-8")
    try:
        return data[skip:].decode(encoding)
    except UnicodeDecodeError as exc:
        pos = skip + exc.start
        if encoding == "utf-8":
            line, column = data.count(b"\n", 0, pos) + 1, pos - data.rfind(b"\n", 0, pos)
            why = f"not UTF-8 text (byte 0x{data[pos]:02x} at line {line}, column {column}); save it as UTF-8"
        elif skip:
            why = f"not {encoding[:6].upper()} text as its BOM says (bad bytes at {pos}); save it as UTF-8"
        else:
            why = "not a text file (NUL bytes, and not UTF-16 or UTF-32 either)"
        raise ScenarioError(source, "(file)", data[max(0, pos - 8):pos + 4], why) from None


class _Builder:
    """Python values from the composed nodes: a fresh copy at each use of an alias."""

    def __init__(self, src: _Source):
        self.src, self.path = src, []  # type: _Source, KeyPath

    def build(self, node: Node) -> Any:
        if isinstance(node, SequenceNode) and node.tag == _SEQ:
            out = []
            for i, child in enumerate(node.value):
                self.path.append(i)
                out.append(self.build(child))
                self.path.pop()
            return out
        if isinstance(node, MappingNode) and node.tag == _MAP:
            return self.mapping(node)
        if isinstance(node, ScalarNode) and node.tag in (_STR, _NULL, _BOOL, _INT, _FLOAT):
            try:
                return _convert(node.tag, node.value)
            except ValueError as exc:
                self.src.fail(self.path, _oneline(node.value, 60), f"{exc} (line {node.start_mark.line + 1})")
        tag = _oneline(node.tag.replace(_TAG, "!!"), 40)
        self.src.fail_at(self.path, node.start_mark,
                         f"tag {tag} is not supported: only plain values, lists and mappings")

    def mapping(self, node: MappingNode) -> dict[Any, Any]:
        out: dict[Any, Any] = {}
        lines: dict[Any, int] = {}
        self._refuse_unspaced(node)
        for key_node, value_node in node.value:
            key = self.build(key_node)
            if not isinstance(key, Hashable) or isinstance(key, list):
                self.src.fail_at(self.path, key_node.start_mark, "a key must be a plain value, not a list")
            if not isinstance(key, str):  # every key of these files is a name
                kind = "null" if key is None else "a boolean" if isinstance(key, bool) else "a number"
                self.src.fail_at(self.path + [key_node.value], key_node.start_mark,
                                 f"a key must be a name, not {kind} ({_oneline(key_node.value or '~', 40)})")
            part, line = key, key_node.start_mark.line + 1
            if key == "<<" and not key_node.style:
                self.src.fail_at(self.path + [part], key_node.start_mark,
                                 "merge keys (<<) are YAML 1.1, not supported; write the keys out")
            if key in out:
                self.src.fail(self.path + [part], self.src.line_text(line - 1),
                              f"duplicate key: first on line {lines[key]}, again on line {line}")
            lines[key] = line
            self.path.append(part)
            out[key] = self.build(value_node)
            self.path.pop()
        return out

    def _refuse_unspaced(self, node: MappingNode) -> None:
        """``{loc:3,scale:2}`` is YAML for the keys ``loc:3`` and ``scale:2`` without values:
        refused, showing it with the spaces meant."""
        if node.flow_style and any(
                not k.style and ":" in k.value and v.tag == _NULL and not v.value and not v.style
                for k, v in node.value):
            text = self.src.text[node.start_mark.index:node.end_mark.index]
            spaced = re.sub(r"([:,])(?=[^\s,:}\]])", r"\1 ", text)
            self.src.fail(self.path, _oneline(text, 60),
                          f"YAML needs a space after ':' ({_oneline(spaced, 80)})", "(syntax)")


def _convert(tag: str, text: str) -> Any:
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


def _parse(src: _Source) -> Any:
    """The one YAML document in ``src``, or None if there is none."""
    bad = _NOT_PRINTABLE.search(src.text)
    if bad:
        pos, char = bad.start(), bad.group()
        line, column = src.text.count("\n", 0, pos), pos - (src.text.rfind("\n", 0, pos) + 1)
        what = "a NUL byte: this is not a text file" if char == "\0" else \
            f"control character U+{ord(char):04X}, which YAML does not allow"
        src.fail([], src.line_text(line), f"{what} (at {src.where(line, column)})")
    loader = _Loader(src.text)
    try:
        root = loader.get_single_node()
    except _Refused as exc:
        src.fail_at(loader.path, exc.problem_mark, str(exc.problem))
    except yaml.MarkedYAMLError as exc:
        _syntax_error(src, loader.path, exc)
    finally:
        loader.dispose()
    return None if root is None else _Builder(src).build(root)


def _syntax_error(src: _Source, path: KeyPath, exc: yaml.MarkedYAMLError) -> NoReturn:
    mark, cmark = exc.problem_mark or exc.context_mark, exc.context_mark
    problem, context = exc.problem or "", exc.context or ""
    if mark is None:  # pragma: no cover - PyYAML and libyaml mark every syntax error
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


def _did_you_mean(path: str | Path) -> str:
    """For a missing ``NAME`` beside which ``NAME.yaml`` (or ``.yml``) exists, a hint naming it."""
    if Path(path).suffix.lower() in (".yaml", ".yml"):
        return ""
    for suffix in (".yaml", ".yml"):
        if os.path.isfile(f"{path}{suffix}"):
            return f"; did you mean {_oneline(f'{path}{suffix}')}?"
    return ""


def load_mapping(path: str | Path, what: str = "scenario") -> dict[Any, Any]:
    """The top-level mapping of the YAML file ``path`` (``{}`` if it holds no document).

    Raises :class:`ScenarioError` (one line: file, key, text, reason) when the file is
    missing, unreadable, too big, not text, not valid YAML, or breaks a rule of this module.
    """
    name = _oneline(str(path))
    try:
        mode = os.stat(path).st_mode
        if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
            raise ScenarioError(name, "(file)", name, f"not a regular file: not a {what} file")
        with open(path, "rb") as stream:
            data = stream.read(MAX_BYTES + 1)
    except OSError as exc:
        reason = {FileNotFoundError: f"no such {what} file{_did_you_mean(path)}", IsADirectoryError:
                  f"is a directory, not a {what} file"}.get(type(exc)) \
            or f"cannot read it: {(exc.strerror or str(exc)).lower()}"
        raise ScenarioError(name, "(file)", name, reason) from None
    if len(data) > MAX_BYTES:
        raise ScenarioError(name, "(file)", name, f"larger than {MAX_BYTES >> 10} KiB: not a {what} file")
    src = _Source(name, _decode(data, name), echo=Path(path).suffix.lower() in (".yaml", ".yml"))
    raw = _parse(src)
    if raw is not None and not isinstance(raw, dict):
        kind = "a list" if isinstance(raw, list) else f"a single value ({type(raw).__name__})"
        src.fail([], src.line_text(0), f"the top level must be a mapping of keys, not {kind}: not a {what} "
                 "file", "(top level)")
    return raw or {}


def parse_value(text: str, origin: str = "--set KEY") -> Any:
    """One YAML value, e.g. of ``--set KEY=VALUE``, read by the rules of the files.

    Errors name ``origin`` where :func:`load_mapping` names the file.
    """
    if len(text) > MAX_BYTES:
        raise ScenarioError(_oneline(origin), "(value)", text[:40], f"longer than {MAX_BYTES >> 10} KiB")
    try:
        return _parse(_Source(origin, text, inline=True))
    except ScenarioError as exc:
        if exc.key in ("(file)", "(top level)", "(syntax)"):
            raise ScenarioError(exc.file, "(value)", _oneline(text, 60), exc.why) from None
        raise
