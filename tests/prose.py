"""What the tests hold of a message: its parts (file, key, value) and the phrases they assert.

``prose_tests`` counts the test functions whose assertions hold a phrase (issue 31): a string
constant, or the literal parts of an f-string put together, longer than 40 characters with a
space in it, in the test expression of an ``assert`` (not its message).  A test function is
one pytest collects: a ``test*`` function of a ``test_*.py`` module, or a ``test*`` method of
a ``Test*`` class there; a parametrised function counts once.  ``in_order`` asserts the parts
of a message (its keys, values, numbers) in their order; ``error_parts`` splits the one line
``cell`` prints for bad input, so that a test can assert the file, key and value it names
rather than its sentence.  ``python -m tests.prose`` lists the functions it counts.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterator
from pathlib import Path
from typing import NamedTuple

TESTS = Path(__file__).resolve().parent
LONGEST_WORDING = 40


def _test_functions(tree: ast.Module) -> Iterator[ast.FunctionDef | ast.AsyncFunctionDef]:
    functions = (ast.FunctionDef, ast.AsyncFunctionDef)
    for node in tree.body:
        if isinstance(node, functions) and node.name.startswith("test"):
            yield node
        elif isinstance(node, ast.ClassDef) and node.name.startswith("Test"):
            yield from (item for item in node.body
                        if isinstance(item, functions) and item.name.startswith("test"))


def phrases(function: ast.AST) -> list[str]:
    """The phrases the assert statements of ``function`` hold in their test expressions."""
    found = []
    for node in ast.walk(function):
        if isinstance(node, ast.Assert):
            found += [text for text in map(_literal, ast.walk(node.test))
                      if text and len(text) > LONGEST_WORDING and " " in text]
    return found


def _literal(node: ast.AST) -> str | None:
    """The text of a string constant, or the literal parts of an f-string put together."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr):
        return "".join(part.value for part in node.values if isinstance(part, ast.Constant))
    return None


def prose_tests(root: Path = TESTS) -> tuple[list[str], int]:
    """``(offenders, total)``: the names (``path::function``) of the test functions under
    ``root`` whose assertions hold a phrase, and the number of test functions."""
    offenders, total = [], 0
    for path in sorted(root.rglob("test_*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        for function in _test_functions(tree):
            total += 1
            if phrases(function):
                offenders.append(f"{path.relative_to(root)}::{function.name}")
    return offenders, total


def in_order(text: str, *parts: str) -> bool:
    """Whether ``text`` holds each of ``parts`` (the keys, values and numbers a message is
    for), one after the other."""
    at = 0
    for part in parts:
        at = text.find(part, at)
        if at < 0:
            return False
        at += len(part)
    return True


class ErrorLine(NamedTuple):
    """The parts of ``cell: FILE: KEY = VALUE: WHY`` (cell/plumbing/errors.py)."""

    file: str
    key: str
    value: str
    why: str


_ERROR = re.compile(r"^(?:cell: )?(?:error: )?(?P<file>.*?): (?P<key>[\w.\[\]-]+) = "
                    r"(?P<value>.*?): (?P<why>.*)$")


def error_parts(line: str) -> ErrorLine:
    """The file, key, value and reason of the one line a ``ScenarioError`` prints; an
    AssertionError when ``line`` has not that shape."""
    match = _ERROR.match(line.strip())
    assert match, line
    return ErrorLine(**match.groupdict())


if __name__ == "__main__":
    names, count = prose_tests()
    print("\n".join(names))
    print(f"{len(names)} of {count} test functions hold a phrase ({len(names) / count:.1%})")
