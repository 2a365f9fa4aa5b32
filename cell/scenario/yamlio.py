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
offending text, reason, on one line.

The library: PyYAML's parser (libyaml's when PyYAML has it), through its public event stream
(``yaml.parse``), read in :mod:`cell.scenario.yaml_values`; nothing of PyYAML is subclassed.
Why neither library's loader: PyYAML's ``safe_load`` is YAML 1.1 (``no`` is False, ``1e3`` a
string, ``0777`` 511, ``1:30`` 5400), keeps the last of two equal keys and no line to name,
and checks on its data cannot undo that (``False`` does not say whether ``no`` or ``off`` was
written); ruamel.yaml 0.19's loaders, YAML 1.2 by default, still read ``1_000`` as 1000,
``0b101`` as 5 and dates as dates, apply merge keys and recurse (20,000 ``[`` is a
RecursionError).  Why not ruamel.yaml's parser under the same two passes (tried: it gave the
same values on the built-in files): its pure-Python scanner refuses a tab between tokens
(``parts: 5<TAB># five``, ``key:<TAB>value``: valid YAML, which libyaml reads; PyYAML's own
Python scanner, used only where PyYAML lacks libyaml, refuses the first too), words some
errors ``but found ('<scalar>',)``, takes 7 ms on ``baseline.yaml`` (8 KB, mostly comments)
where libyaml takes 0.2 ms, and costs a 40 ms import where PyYAML's is 20 ms.  The YAML 1.2
readings come from the core schema's table either way.  Checked once against the reader this
replaced (one that subclassed PyYAML's composer; the comparison is not kept) on 22,311
documents (the built-in files, the hostile suites' cases, mutations, random text), with
libyaml and with PyYAML's Python parser: the same values and the same messages, except 52 (libyaml) and 72
(Python) flow mappings with a list as a key (``{[a]: 1}``), a traceback then, one line now.
Start-up is unchanged: reading ``baseline.yaml`` takes 1.2 ms (1.1 ms before), importing
this module and PyYAML about 20 ms, as before (``cell --help`` imports neither), and a cold ``cell
run baseline`` 0.73 s against 0.72 s before (medians of 11 runs, interleaved, on a busy machine).
"""

from __future__ import annotations

import codecs
import os
import re
import stat
from pathlib import Path
from typing import Any

from cell.plumbing.errors import ScenarioError
from cell.plumbing.errors import one_line as _oneline
from cell.scenario.yaml_values import MAX_DEPTH, MAX_INT_DIGITS, MAX_NODES, Builder, Source, Walk

__all__ = ["MAX_BYTES", "MAX_DEPTH", "MAX_INT_DIGITS", "MAX_NODES", "load_mapping", "parse_value"]

MAX_BYTES = 1 << 20  #: largest file read (bytes); scenario and sweep files are a few kilobytes
#: What YAML allows in a stream: tab, line breaks and printable characters.
_NOT_PRINTABLE = re.compile("[^\t\n\r\x20-\x7e\x85\xa0-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


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


def _parse(src: Source) -> Any:
    """The one YAML document in ``src``, or None if there is none."""
    bad = _NOT_PRINTABLE.search(src.text)
    if bad:
        pos, char = bad.start(), bad.group()
        line, column = src.text.count("\n", 0, pos), pos - (src.text.rfind("\n", 0, pos) + 1)
        what = "a NUL byte: this is not a text file" if char == "\0" else \
            f"control character U+{ord(char):04X}, which YAML does not allow"
        src.fail([], src.line_text(line), f"{what} (at {src.where(line, column)})")
    walk = Walk(src)
    events = walk.run()
    return Builder(src, walk.unspaced).build(events) if events else None


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
    src = Source(name, _decode(data, name), echo=Path(path).suffix.lower() in (".yaml", ".yml"))
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
        return _parse(Source(origin, text, inline=True))
    except ScenarioError as exc:
        if exc.key in ("(file)", "(top level)", "(syntax)"):
            raise ScenarioError(exc.file, "(value)", _oneline(text, 60), exc.why) from None
        raise
