"""The README as a user follows it: its command table against each command's options, and
every Python block in README.md and docs/ run as written."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from cell.cli.parser import COMMANDS, build_parser

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")
#: Options the table leaves to its prose: help, and --set (every scenario command takes it).
UNLISTED = {"-h", "--help", "--set"}


def subparsers() -> dict[str, argparse.ArgumentParser]:
    action = next(a for a in build_parser()._actions
                  if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def table_rows() -> dict[str, str]:
    """``cell NAME ...`` as each row of the command table shows it, by command name."""
    start = README.index("| command | what it does |")
    table = README[start:README.index("\n\n", start)]
    shown = {}
    for line in table.splitlines()[2:]:
        first = line.split(" | ")[0]
        for span in re.findall(r"`(cell [^`]*)`", first):
            shown[span.split()[1]] = span.replace("\\|", "|")
    return shown


def test_the_command_table_lists_every_command_with_all_its_options():
    rows, parsers = table_rows(), subparsers()
    assert sorted(rows) == sorted(COMMANDS)
    for name, row in rows.items():
        options = {o for a in parsers[name]._actions for o in a.option_strings} - UNLISTED
        assert set(re.findall(r"--[a-z][a-z-]*", row)) == options, name


def python_blocks() -> list[tuple[str, str]]:
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    return [(f"{page.name}:{i}", block) for page in pages
            for i, block in enumerate(re.findall(r"```python\n(.*?)```",
                                                 page.read_text(encoding="utf-8"), re.S))]


def test_the_readme_has_a_python_block():
    assert any(where.startswith("README.md") for where, _ in python_blocks())


@pytest.mark.parametrize("where,block", python_blocks(), ids=[w for w, _ in python_blocks()])
def test_a_python_block_runs_as_written(where, block, tmp_path, monkeypatch):
    """In a fresh namespace, as a reader pastes it: every name it uses it imports itself."""
    monkeypatch.chdir(tmp_path)
    exec(compile(block, where, "exec"), {"__name__": "__main__"})
