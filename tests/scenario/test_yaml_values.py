"""The YAML reader on PyYAML's event stream: the same data from every built-in file with either
parser, the YAML 1.2 core schema's readings on tricky documents, and nothing of PyYAML subclassed."""

from __future__ import annotations

import ast
import math
from pathlib import Path

import pytest
import yaml

from cell.plumbing.errors import ScenarioError
from cell.scenario import yaml_values
from cell.scenario.yamlio import load_mapping, parse_value

LOADERS = {"python": yaml.SafeLoader, **({"libyaml": yaml.CSafeLoader} if yaml.__with_libyaml__ else {})}
BUILT_IN = sorted((Path(__file__).resolve().parents[2] / "cell" / "scenarios").glob("*.yaml"))


@pytest.fixture(params=list(LOADERS), autouse=True)
def loader(request, monkeypatch):
    """Every test with PyYAML's pure-Python parser and, when there, with libyaml's."""
    monkeypatch.setattr(yaml_values, "LOADER", LOADERS[request.param])
    return request.param


def test_the_built_in_files_are_all_here():
    """Scenarios, sweeps, studies and the dynamics model: each kind is among them."""
    names = {p.stem for p in BUILT_IN}
    assert {"baseline", "microbot_dynamics", "table_7_1", "stress", "optimize", "assumptions"} <= names


@pytest.mark.parametrize("path", BUILT_IN, ids=lambda p: p.name)
def test_built_in_files_read_the_same_with_either_parser(path, monkeypatch):
    """Same data with libyaml's parser and PyYAML's own, and the same as PyYAML's ``safe_load``
    (these files hold nothing that YAML 1.1 and 1.2 read differently)."""
    got = load_mapping(path)
    assert got == yaml.safe_load(path.read_text(encoding="utf-8"))
    for other in LOADERS.values():
        monkeypatch.setattr(yaml_values, "LOADER", other)
        assert load_mapping(path) == got


#: YAML text -> its value by the YAML 1.2 core schema (yaml.org/spec/1.2.2, §10.3.2), the
#: spec's other rules (block scalars §8.1, documents §9.1) and the rules of cell's files.
TRICKY = {
    "-.5": -0.5, "+.5e-2": 0.005, "1.e5": 1e5, "-0": 0, "00": 0, "007": 7,
    ".e5": ".e5", "1e": "1e", "+0o7": "+0o7", "-0x1": "-0x1", "0o8": "0o8", "0x": "0x",
    ".Nan": ".Nan", "tRUE": "tRUE", "~x": "~x", "nullx": "nullx", "TRUE ": True,
    "9" * 40: int("9" * 40), "-" + "9" * 40: -int("9" * 40),
    "!!str 1e3": "1e3", "!!null ''": None, "!!float 0x10": 16.0, "!!str": "",
    "|\n  x\n  y\n": "x\ny\n", ">-\n  x\n\n  y\n": "x\ny", "'it''s'": "it's", '"\\x41\\u263A"': "A☺",
    "{'<<': 1}": {"<<": 1}, "--- !!map\na: 1\n": {"a": 1}, "a: 1\n...\n": {"a": 1},
    "[&a [1, &b [2]], *b, *a]": [[1, [2]], [2], [1, [2]]],
    "{&k a: 1, b: *k}": {"a": 1, "b": "a"},
}


@pytest.mark.parametrize("text", TRICKY)
def test_tricky_documents(text):
    assert parse_value(text) == TRICKY[text]


def test_aliases_are_copies_at_every_depth():
    doc = parse_value("[&a [1, &b [2]], *b, *a]")
    doc[0][1].append(3)
    assert doc[1] == [2] and doc[2] == [1, [2]]
    assert math.isnan(parse_value("!!float .nan"))


#: YAML text -> (key named, words of the one line)
REFUSED = {
    "{&k a: 1, *k : 2}": ("a", "duplicate key: first on line 1, again on line 1"),
    "a: &x 1\nb: &x 2\n": (None, "found duplicate anchor 'x'"),
    "{[a]: 1}": ("(value)", "a key must be a plain value, not a list"),  # a traceback before
    "a: !!int 1.5": ("a", "not an integer"),
    "a: !!bool 1": ("a", "not a boolean: write true or false"),
    "a: !!map [1]": ("a", "tag !!map is not supported"),
    "a: !!seq {b: 1}": ("a", "tag !!seq is not supported"),
    "{<<: 1}": ("<<", "merge keys (<<) are YAML 1.1"),
    "a: " + "9" * 41: ("a", "an integer of 41 digits; at most 40"),
    "a: 1\n...\n---\nb: 2\n": ("(value)", "expected a single document in the stream, but found another"),
    "a: [1, *nowhere]": ("a[1]", "found undefined alias 'nowhere'"),
    "a:\n  b: [{c: &x [*x]}]\n": ("a.b[0].c[0]", "an alias refers to a collection that holds it"),
}


@pytest.mark.parametrize("text", REFUSED)
def test_refused_in_one_line_naming_the_key(text):
    key, words = REFUSED[text]
    with pytest.raises(ScenarioError) as info:
        parse_value(text, "--set x")
    assert words in str(info.value) and "\n" not in str(info.value)
    assert key is None or info.value.key == key, str(info.value)


def test_nothing_of_pyyaml_is_subclassed():
    """The reader uses PyYAML's parser through ``yaml.parse`` only: no class of it extends
    one of PyYAML's."""
    for module in (yaml_values, __import__("cell.scenario.yamlio", fromlist=["x"])):
        tree = ast.parse(Path(module.__file__).read_text(encoding="utf-8"))
        bases = [ast.unparse(b) for c in ast.walk(tree) if isinstance(c, ast.ClassDef) for b in c.bases]
        assert not any("yaml" in b.lower() or b in ("Composer", "Parser", "Scanner", "Reader") for b in bases)
