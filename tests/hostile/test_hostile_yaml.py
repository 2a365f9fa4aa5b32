"""Hostile files and ``--set`` text: encodings, syntax, bombs, duplicates, odd files.

Each case is given to ``cell run`` (and the file cases to ``cell path`` and ``cell mintime``
too): refused in one short line naming the file (or ``--set KEY``), exit 2, nothing written,
in well under a second whatever the size of the input.
"""

from __future__ import annotations

import codecs
import os
import time
from pathlib import Path

import pytest

from .harness import cli, ran_sanely, refused

BOMB = "a: &a [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{chr(98 + i)}: &{chr(98 + i)} [{', '.join([f'*{chr(97 + i)}'] * 10)}]\n" for i in range(8))


def _bomb_as(key: str) -> str:
    """A billion-laughs document whose last alias is the value of ``key`` (dotted)."""
    *sections, leaf = key.split(".")
    text = "x-anchors:\n" + "".join("  " + line + "\n" for line in BOMB.splitlines())
    indent = ""
    for part in sections:
        text += f"{indent}{part}:\n"
        indent += "  "
    return text + f"{indent}{leaf}: *i\n"


#: (id, bytes of the file, words the one line must hold): one case per rule of the reader
#: (tests/hostile/harness.py), e.g. one syntax error for the parser's one way of reporting it,
#: one alias bomb (a bomb as the value of a key is counted by the same rule), one non-name key
#: (a boolean or null key meets the same check as a number)
FILES: list[tuple[str, bytes, tuple[str, ...]]] = [
    ("latin-1", "name: caf\xe9\n".encode("latin-1"), ("not UTF-8", "line 1")),
    ("binary", bytes(range(256)) * 8, ("(file)",)),
    ("NUL in text", b"name: a\x00b\n", ("NUL",)),
    ("control character", b"name: a\x07b\n", ("U+0007",)),
    ("UTF-16 BOM, bad", codecs.BOM_UTF16_LE + b"\x00\xd8", ("UTF-16",)),
    ("UTF-8 BOM then latin-1", codecs.BOM_UTF8 + "name: \xe9\n".encode("latin-1"), ("not UTF-8",)),
    ("too big", b"# " + b"x" * (1 << 20) + b"\n", ("KiB",)),
    ("top-level list", b"- run\n- path\n", ("top level", "not a list")),
    ("unclosed flow", b"run: {parts: 5\n", ("invalid YAML", "line 1")),
    ("bad indent", b"run:\n  parts: 5\n seed: 3\n", ("invalid YAML", "line 3")),
    ("tab indent", b"run:\n\tparts: 5\n", ("invalid YAML", "line 2")),
    ("two documents", b"name: a\n---\nname: b\n", ("single document",)),
    ("duplicate top key", b"run: {parts: 5}\nrun: {parts: 6}\n", ("duplicate key", "line 2")),
    ("duplicate nested key", b"run:\n  parts: 5\n  parts: 6\n", ("run.parts", "duplicate key")),
    ("merge key", b"base: &b {parts: 5}\nrun:\n  <<: *b\n", ("merge keys",)),
    ("python tag", b"run: !!python/object/apply:os.system [ls]\n", ("tag", "not supported")),
    ("binary tag", b"name: !!binary aGVsbG8=\n", ("tag",)),
    ("local tag", b"name: !mine x\n", ("tag",)),
    ("list as key", b"? [a, b]\n: c\n", ("key must be a plain value",)),
    ("self-referencing alias", b"a: &a [*a]\n", ("alias",)),
    ("undefined alias", b"name: *nowhere\n", ("invalid YAML",)),
    ("20,000 [", b"name: " + b"[" * 20000 + b"\n", ("nested deeper",)),
    ("200 levels of block lists", b"name:\n" + b"".join(b"  " * i + b"-\n" for i in range(1, 200)),
     ("nested deeper",)),
    ("alias bomb at the top", BOMB.encode(), ("more than 10,000 values",)),
    ("40,000 keys", b"".join(b"k%d: 1\n" % i for i in range(40000)), ("more than 10,000 values",)),
    ("a 200,000-character key", b"k" * 200000 + b": 1\n", ("(syntax)", "1024 characters")),
    ("unknown section", b"robt: {}\n", ("robt", "unknown key")),
    ("unknown key", b"run: {prts: 5}\n", ("run.prts", "unknown key")),
    ("section as list", b"run: [1, 2]\n", ("run",)),
    ("integer key", b"1: x\n", ("a key must be a name, not a number (1)",)),
    ("float key in a section", b"run: {1.5: x}\n", ("run.1.5", "not a number")),
    ("sexagesimal parts", b"run: {parts: 1:30}\n", ("run.parts", "'1:30'")),
    ("YAML 1.1 yes", b"mintime: {acceleration_bounds: yes}\n", ("mintime.acceleration_bounds",)),
    ("octal 0777 is decimal 777, too many parts", b"run: {parts: 0777, seed: 0o17}\n" + b"x: 1\n", ("x",)),
    ("4,000-digit seed", b"run: {seed: " + b"9" * 4000 + b"}\n", ("run.seed", "4,000 digits")),
    ("1e300 coordinate", b"path: {bot_in: [1e300, 0, 3]}\n", ("path.bot_in[0]", "at most 1000")),
    ("directive 1.1", b"%YAML 1.1\n---\nrun: {parts: on}\n", ("run.parts",)),
]


@pytest.mark.parametrize("command", ["run", "path", "mintime"])
def test_hostile_files(tmp_path: Path, command: str) -> None:
    """Every file above, refused in one line naming the file, fast, nothing written; ``path`` and
    ``mintime`` read their scenario with the same reader as ``run``, so one file each shows
    they use it."""
    failures = []
    for i, (label, data, words) in enumerate(FILES if command == "run" else FILES[:1]):
        scenario = tmp_path / f"case{i}.yaml"
        scenario.write_bytes(data)
        out = tmp_path / f"out{i}"
        start = time.perf_counter()
        res = cli(command, scenario, "--out", out)
        try:
            assert time.perf_counter() - start < 20.0, "a hang (far above any normal refusal)"
            refused(res, str(scenario), *words, nothing_in=out)
        except AssertionError as exc:
            failures.append(f"{label}: {exc}"[:800])
    assert not failures, "\n".join(failures)


def test_encodings_yaml_allows_are_read(tmp_path: Path) -> None:
    """UTF-8 with a BOM, UTF-16 and UTF-32 (with and without BOM) are YAML text: they run."""
    text = "name: encoded\nrun: {parts: 3}\n"
    kinds = ("utf-16", "utf-16-le", "utf-16-be", "utf-32", "utf-32-be")
    encoded = [codecs.BOM_UTF8 + text.encode()] + [text.encode(e) for e in kinds]
    for i, data in enumerate(encoded):
        scenario = tmp_path / f"enc{i}.yaml"
        scenario.write_bytes(data)
        out = tmp_path / f"out{i}"
        ran_sanely(cli("run", scenario, "--out", out), out, 3)


def test_yaml_12_numbers_are_read(tmp_path: Path) -> None:
    """``21e0``, ``2.25872e1``, ``+12.5`` and friends are the numbers they look like."""
    scenario = tmp_path / "numbers.yaml"
    scenario.write_text("controller: {policy: non-adaptive, ideal_cycle_s: 2.25872e1}\n"
                        "belts: {spacing_in: 45e0, spacing_tol_in: +.25}\nrun: {parts: 0x4}\n")
    out = tmp_path / "out"
    summary = ran_sanely(cli("run", scenario, "--out", out), out, 4)
    assert summary.ideal_cycle_s == pytest.approx(22.5872)


def test_files_that_are_not_files(tmp_path: Path) -> None:
    """A directory, a missing file, a FIFO (which would block a reader forever; a device is the
    same rule)."""
    fifo = tmp_path / "fifo.yaml"
    os.mkfifo(fifo)
    (tmp_path / "dir.yaml").mkdir()
    cases = [(tmp_path / "dir.yaml", "is a directory"), (tmp_path / "missing.yaml", "no such scenario file"),
             (fifo, "not a regular file")]  # /dev/zero: the same rule as the FIFO
    for path, words in cases:
        out = tmp_path / "out"
        refused(cli("run", path, "--out", out), str(path), words, nothing_in=out)


def test_unreadable_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Permission denied on the scenario (simulated: the suite may run as root)."""
    scenario = tmp_path / "locked.yaml"
    scenario.write_text("name: x\n")
    real_open = open

    def denying(file, *args, **kwargs):  # noqa: ANN001, ANN002, ANN003, ANN202
        if os.fspath(file) == str(scenario):
            raise PermissionError(13, "Permission denied", str(scenario))
        return real_open(file, *args, **kwargs)

    monkeypatch.setattr("builtins.open", denying)
    out = tmp_path / "out"
    refused(cli("run", scenario, "--out", out), str(scenario), "permission denied", nothing_in=out)


#: (id, --set arguments, words)
SETS: list[tuple[str, list[str], tuple[str, ...]]] = [
    ("no =", ["run.parts"], ("KEY=VALUE",)),
    ("unclosed list", ["run.parts=[1,"], ("--set run.parts", "invalid YAML")),
    ("two documents", ["name=a\n---\nb"], ("--set name",)),
    ("empty part", ["run..parts=5"], ("empty part",)),
    ("unknown section", ["nosuch.key=5"], ("nosuch",)),
    ("unknown key", ["run.prts=5"], ("run.prts", "unknown key")),
    ("into a value", ["run.parts.x=5"], ("run.parts",)),
    ("section as scalar", ["run=5"], ("run",)),
    ("section to null", ["run=~", "run.parts=3"], ()),
    ("alias bomb", ["name=" + "{" + BOMB.replace("\n", ", ").rstrip(", ") + "}"], ("more than 10,000",)),
    ("deep nesting", ["name=" + "[" * 5000], ("nested deeper",)),
    ("tag", ["run.parts=!!python/object:os.system x"], ("tag",)),
    ("duplicate keys", ["run={parts: 3, parts: 4}"], ("duplicate key",)),
    ("control character", ["name=a\x07b"], ("U+0007",)),
    ("NUL", ["name=a\x00b"], ("NUL",)),
    ("4,000 digits", ["run.seed=" + "9" * 4000], ("4,000 digits",)),
    ("2 MiB value", ["name=" + "x" * (2 << 20)], ("KiB",)),
]


def test_hostile_set_values(tmp_path: Path) -> None:
    failures = []
    for i, (label, sets, words) in enumerate(SETS):
        out = tmp_path / f"out{i}"
        args = [a for s in sets for a in ("--set", s)]
        res = cli("run", "baseline", *args, "--out", out)
        try:
            if label == "section to null":  # an empty section keeps its defaults
                ran_sanely(res, out, 3)
                continue
            refused(res, *words, nothing_in=out)
        except AssertionError as exc:
            failures.append(f"{label}: {exc}"[:800])
    assert not failures, "\n".join(failures)


def test_set_into_an_empty_section_of_a_file(tmp_path: Path) -> None:
    scenario = tmp_path / "empty_run.yaml"
    scenario.write_text("run:\nmintime:\n")
    out = tmp_path / "out"
    ran_sanely(cli("run", scenario, "--set", "run.parts=4", "--out", out), out, 4)


def test_errors_name_the_file_once_and_quote_no_foreign_file(tmp_path: Path) -> None:
    """A non-YAML file (``/etc/passwd`` in a sweep's ``base``): named, its lines not echoed."""
    secret = tmp_path / "secrets.txt"
    secret.write_text("root:x:0:0:the password is swordfish\nmore: [\n")
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(f"base: {secret}\nreplications: 2\n")
    res = cli("sweep", sweep, "--workers", "1", "--out", tmp_path / "out")
    line = refused(res, str(secret), nothing_in=tmp_path / "out")
    assert "swordfish" not in line and "root:x" not in line
