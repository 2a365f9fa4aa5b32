"""The YAML reader: hostile input gives one short line naming file and key; valid input YAML 1.2 values."""

from __future__ import annotations

import math
import time
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cell.plumbing.errors import ScenarioError, short
from cell.scenario import yaml_values
from cell.scenario.yamlio import MAX_BYTES, load_mapping, parse_value
from tests.prose import in_order

LOADERS = ["python"] + (["libyaml"] if yaml.__with_libyaml__ else [])
SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
#: How long a hostile input may take before it counts as a hang: far above any normal time
#: (milliseconds) even on a loaded machine, far below what an unguarded blow-up takes.
HANG_S = 10.0


@pytest.fixture(params=LOADERS, autouse=True)
def loader(request, monkeypatch):
    """Every test runs with PyYAML's pure-Python parser and, when there, with libyaml's."""
    if request.param == "python":
        monkeypatch.setattr(yaml_values, "LOADER", yaml.SafeLoader)
    return request.param


def _bomb(levels: int) -> bytes:
    lines = ['l0: &l0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    lines += [f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * 9) + "]" for i in range(1, levels + 1)]
    return "\n".join(lines).encode() + b"\n"


# name -> (file bytes, key named in the error (None: any), words of the reason)
HOSTILE = {
    "not utf-8": (b"name: \xff\n", "(file)", "not UTF-8 text (byte 0xff at line 1, column 7)"),
    "binary garbage": (bytes(range(256)) * 8, "(file)", "not a text file"),
    "png header": (b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0", "(file)", "not UTF-8"),
    "nul byte": (b"run:\n  parts: 1\0\n", "(file)", "NUL byte"),
    "control character": (b"name: \x1b[31mred\n", "(file)", "control character U+001B"),
    "bad utf-16 after its bom": (b"\xff\xfea\0:\0 \0\x00\xd8", "(file)", "not UTF-16"),
    "20000 nested [": (b"[" * 20000, None, "nested deeper than 32 levels"),
    "20000 nested {": (b"a: " + b"{" * 20000, None, "nested deeper than 32 levels"),
    "deep block nesting": ("".join("  " * i + f"k{i}:\n" for i in range(40)).encode(), None,
                           "nested deeper than 32 levels"),
    "deep through aliases": ("".join(f"a{i}: &a{i} [*a{i - 1}]\n" if i else "a0: &a0 [1]\n"
                                     for i in range(40)).encode(), None, "nested deeper than 32 levels"),
    "6-level alias bomb": (_bomb(6), None, "more than 10,000 values"),
    "9-level alias bomb": (_bomb(9), None, "more than 10,000 values"),
    "recursive alias": (b"a: &a [1, *a]\n", "a[1]", "refers to a collection that holds it"),
    "undefined alias": (b"a: *nowhere\n", None, "undefined alias"),
    "too many values": (b"- 1\n" * 10_001, None, "more than 10,000 values"),
    "duplicate top-level key": (b"a: 1\nb: 2\na: 3\n", "a",
                                "duplicate key: first on line 1, again on line 3"),
    "duplicate nested key": (b"belts:\n  input_nominal_in_s: 3\n  output_nominal_in_s: 5\n"
                             b"  input_nominal_in_s: 4\n", "belts.input_nominal_in_s", "duplicate key"),
    "duplicate key in a list item": (b"robot:\n  motors:\n    - {a: 1, a: 2}\n", "robot.motors[0].a",
                                     "duplicate key"),
    "duplicate after a quoted twin": (b"a: 1\n'a': 2\n", "a", "duplicate key"),
    "syntax: unclosed list": (b"a: [1,", "a", "invalid YAML at the end"),
    "syntax: bad indentation": (b"run:\n  parts: 1\n seed: 2\n", None, "invalid YAML at line 3"),
    "syntax: tab indentation": (b"run:\n\tparts: 1\n", None, "invalid YAML at line 2"),
    "syntax: unterminated quote": (b'name: "abc\n', None, "invalid YAML"),
    "two documents": (b"a: 1\n---\nb: 2\n", None, "but found another document"),
    "top-level list": (b"- a\n- b\n", "(top level)", "must be a mapping of keys, not a list"),
    "top-level scalar": (b"just words\n", "(top level)", "must be a mapping of keys, not a single value"),
    "python tag": (b"a: !!python/object/apply:os.system [ls]\n", "a", "tag !!python/object/apply:os.system"),
    "binary tag": (b"a: !!binary aGVsbG8=\n", "a", "tag !!binary is not supported"),
    "set tag": (b"a: !!set {x, y}\n", "a", "tag !!set is not supported"),
    "local tag": (b"a: !thing 1\n", "a", "tag !thing is not supported"),
    "merge key": (b"base: &b {x: 1}\nrun:\n  <<: *b\n", "run.<<", "merge keys"),
    "tagged int that is not": (b"robot:\n  steps: [1, 2, !!int x]\n", "robot.steps[2]", "not an integer"),
    "tagged bool that is not": (b"a: !!bool yes\n", "a", "not a boolean"),
    "list as a key": (b"? [a, b]\n: 1\n", None, "a key must be a plain value"),
    "4000-digit seed": (b"run:\n  seed: " + b"7" * 4000 + b"\n", "run.seed", "4,000 digits"),
    "huge hex": (b"a: 0x" + b"f" * 60 + b"\n", "a", "at most 40"),
    "too big": (b"a: 1\n" + b"#" * MAX_BYTES, "(file)", "larger than 1024 KiB"),
}


def _assert_one_line(exc: ScenarioError, path: Path, key: str | None) -> str:
    text = str(exc)
    assert "\n" not in text and "\r" not in text
    assert len(text) < 300, text
    assert text.startswith(f"{path}: ")
    if key is not None:
        assert exc.key == key, text
    return text


@pytest.mark.parametrize("name", HOSTILE)
def test_hostile_files_give_one_short_line(name, tmp_path):
    data, key, words = HOSTILE[name]
    path = tmp_path / "bad.yaml"
    path.write_bytes(data)
    start = time.perf_counter()
    with pytest.raises(ScenarioError) as info:
        load_mapping(path)
    assert time.perf_counter() - start < HANG_S  # a guard against blow-ups, not a speed test
    assert words in _assert_one_line(info.value, path, key)


def test_alias_bombs_are_refused_fast(tmp_path):
    path = tmp_path / "bomb.yaml"
    for levels in (6, 9, 30):
        path.write_bytes(_bomb(levels))
        start = time.perf_counter()
        with pytest.raises(ScenarioError, match="more than 10,000 values"):
            load_mapping(path)
        assert time.perf_counter() - start < HANG_S  # unguarded, a 30-level bomb never ends


@pytest.mark.parametrize("problem, words", [
    (FileNotFoundError(2, "No such file or directory"), "no such sweep file"),
    (IsADirectoryError(21, "Is a directory"), "is a directory, not a sweep file"),
    (PermissionError(13, "Permission denied"), "cannot read it: permission denied"),
    (OSError(5, "Input/output error"), "cannot read it: input/output error"),
])
def test_unreadable_files(problem, words, tmp_path, monkeypatch):
    path = tmp_path / "s.yaml"
    path.write_text("a: 1\n")

    def refuse(*args, **kwargs):
        raise problem
    monkeypatch.setattr("builtins.open", refuse)
    with pytest.raises(ScenarioError) as info:
        load_mapping(path, what="sweep")
    assert words in _assert_one_line(info.value, path, "(file)")


def test_missing_file_and_directory_for_real(tmp_path):
    with pytest.raises(ScenarioError, match="no such scenario file"):
        load_mapping(tmp_path / "nope.yaml")
    with pytest.raises(ScenarioError, match="is a directory"):
        load_mapping(tmp_path)


VALUES = {
    "21e0": 21.0, "2.25872e1": 22.5872, "1e-3": 0.001, "+12.5": 12.5, ".5": 0.5, "5.": 5.0, "-2E+2": -200.0,
    ".inf": math.inf, "-.inf": -math.inf, "+.INF": math.inf, "1e400": math.inf,
    "12": 12, "-5": -5, "+7": 7, "0777": 777, "0o777": 511, "0x1F": 31, "0": 0,
    "340282366920938463463374607431768211455": 2**128 - 1,
    "1:30": "1:30", "1_000": "1_000", "2001-12-14": "2001-12-14", "0b101": "0b101", "1.2.3": "1.2.3",
    "yes": "yes", "no": "no", "on": "on", "off": "off", "y": "y", "Yes": "Yes",
    "true": True, "True": True, "TRUE": True, "false": False, "False": False, "FALSE": False,
    "~": None, "null": None, "Null": None, "": None,
    "'12'": "12", '"1e3"': "1e3", "!!str 12": "12", "!!float 3": 3.0, "!!int '0x10'": 16,
    "[1, 2.5, x]": [1, 2.5, "x"], "{a: 1}": {"a": 1},
}


@pytest.mark.parametrize("text", VALUES)
def test_yaml_1_2_values(text, tmp_path):
    path = tmp_path / "v.yaml"
    path.write_text(f"v: {text}\n")
    assert load_mapping(path) == {"v": VALUES[text]}
    assert parse_value(text) == VALUES[text]


def test_nan():
    assert math.isnan(parse_value(".nan")) and math.isnan(parse_value(".NaN"))


@pytest.mark.parametrize("encoding", ["utf-8-sig", "utf-16", "utf-16-le", "utf-16-be", "utf-32", "utf-32-le"])
def test_encodings_with_and_without_bom(encoding, tmp_path):
    path = tmp_path / "e.yaml"
    path.write_bytes("name: Zürich ✓\nrun: {parts: 10}\n".encode(encoding))
    assert load_mapping(path) == {"name": "Zürich ✓", "run": {"parts": 10}}


@pytest.mark.parametrize("text", ["", "\n\n", "# only a comment\n", "---\n", "--- # c\n...\n", "~\n"])
def test_empty_documents_are_empty_mappings(text, tmp_path):
    path = tmp_path / "e.yaml"
    path.write_text(text)
    assert load_mapping(path) == {}


def test_crlf_and_aliases_give_unshared_copies(tmp_path):
    path = tmp_path / "a.yaml"
    path.write_bytes(b"base: &b {scale: 10}\r\narrivals: {params: *b}\r\n")
    raw = load_mapping(path)
    assert raw == {"base": {"scale": 10}, "arrivals": {"params": {"scale": 10}}}
    raw["base"]["scale"] = 99  # a later --set on one place must not change the other
    assert raw["arrivals"]["params"]["scale"] == 10


@pytest.mark.parametrize("path", sorted(SCENARIOS.glob("*.yaml")), ids=lambda p: p.name)
def test_shipped_scenarios_read_as_before(path):
    assert load_mapping(path) == yaml.safe_load(path.read_text())


def test_parse_value_for_the_command_line():
    assert parse_value("100", "--set run.parts") == 100
    flow = "{distribution: expon, params: {scale: 10}}"
    assert parse_value(flow) == {"distribution": "expon", "params": {"scale": 10}}
    for text, key, words in [("{distribution: expon", "(value)", "invalid YAML at the end"),
                             ("[1, 2", "(value)", "invalid YAML"),
                             ("{a: 1, a: 2}", "a", "duplicate key"),
                             ("!!python/name:os.system", "(value)", "not supported"),
                             ("[" * 5000, None, "nested deeper"),
                             ("x\0y", "(value)", "NUL byte")]:
        with pytest.raises(ScenarioError) as info:
            parse_value(text, "--set arrivals")
        message = str(info.value)
        assert message.startswith("--set arrivals: ") and "\n" not in message and len(message) < 300
        assert key in (None, info.value.key) and words in message, message


def test_parse_value_column_on_one_line():
    with pytest.raises(ScenarioError, match="at column 6"):
        parse_value("[1, ]]")


@pytest.mark.parametrize("loader", ["python"], indirect=True)  # no YAML read: one is enough
def test_short_is_short_and_cheap():
    cases = [("a" * 39_000_000, "(39,000,000 characters)"), (list(range(20_000)), "(20,000 items)"),
             ({str(i): "v" * 100 for i in range(50_000)}, "(50,000 items)"),
             (b"\0" * 10**6, "(1,000,000 bytes)"),
             (10**5000, "digits)"), (set(range(10**5)), "items)"), (tuple(range(100)), "(100 items)")]
    deep: list[object] = []
    for _ in range(100_000):
        deep = [deep]
    loop: list[object] = [1]
    loop.append(loop)
    cases += [(deep, "(1 item)"), (loop, "")]
    for value, size in cases:
        start = time.perf_counter()
        text = short(value)
        assert time.perf_counter() - start < HANG_S  # an unbounded repr of these takes minutes
        assert len(text) < 120 and "\n" not in text and text.endswith(size), text
    assert short("abc") == "'abc'" and short([1, "a", None]) == "[1, 'a', None]" and short((1,)) == "(1,)"
    assert short({"a": [1, 2]}) == "{'a': [1, 2]}" and short(set()) == "set()" and short(2.5) == "2.5"
    assert short("a" * 200, limit=20).startswith("'aaaaaaaaaaaaaaaaa…'")
    assert short(list(range(1000)), limit=20) == "[0, 1, 2, 3, 4, …] (1,000 items)"


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.text())
def test_any_text_parses_or_gives_one_line(text):
    _only_scenario_errors(lambda: parse_value(text, "--set x"))


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.text(alphabet="[]{}:,-&*!|>'\"#?%@` \n\tab01.e~", max_size=60))
def test_yaml_punctuation_parses_or_gives_one_line(text):
    _only_scenario_errors(lambda: parse_value(text, "--set x"))


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.binary(max_size=200))
def test_any_bytes_load_or_give_one_line(tmp_path, data):
    path = tmp_path / "h.yaml"
    path.write_bytes(data)
    _only_scenario_errors(lambda: load_mapping(path))


def _only_scenario_errors(read):
    try:
        read()
    except ScenarioError as exc:
        assert "\n" not in str(exc) and len(str(exc)) < 400, str(exc)


@pytest.mark.parametrize("text, spaced", [
    ("{loc:3,scale:2}", "{loc: 3, scale: 2}"),
    ("{loc:3, scale: 2}", "{loc: 3, scale: 2}"),
    ("{shape:-1.5}", "{shape: -1.5}"),
])
def test_a_flow_mapping_without_spaces_after_colons_says_so(text, spaced, tmp_path):
    """``{loc:3}`` is YAML for a key ``loc:3`` with no value: on the command line and in a
    file, the error shows the mapping with the spaces meant."""
    with pytest.raises(ScenarioError) as info:
        parse_value(text, "--set arrivals.params")
    error = info.value
    assert (error.file, error.key, error.value) == ("--set arrivals.params", "(value)", text)
    assert in_order(error.why, "a space after ':'", f"({spaced})")
    path = tmp_path / "s.yaml"
    path.write_text(f"arrivals:\n  params: {text}\n")
    with pytest.raises(ScenarioError) as info:
        load_mapping(path)
    assert info.value.key == "arrivals.params" and f"({spaced})" in str(info.value)


@pytest.mark.parametrize("text, value", [
    ('{"loc:3": 1}', {"loc:3": 1}),        # quoted: a key with a colon, as asked
    ("{url: http://x}", {"url": "http://x"}),
    ("{a}", {"a": None}),                   # a key without a value, but no colon in it
    ("[loc:3]", ["loc:3"]),
])
def test_colons_yaml_reads_as_meant_are_left_alone(text, value):
    assert parse_value(text) == value
