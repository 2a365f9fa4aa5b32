"""Every test the docs cite (``tests/FILE::TEST``) exists, so a reader who runs it finds it."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PAGES = [ROOT / "README.md", ROOT / "reports" / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
CITED = re.compile(r"tests/([\w/]+\.py)((?:::\w+)*)")


def defined(path: Path) -> set[str]:
    """``name`` and ``Class::name`` of every function and class in a test file."""
    names: set[str] = set()
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        if isinstance(node, ast.ClassDef):
            names |= {f"{node.name}::{m.name}" for m in node.body
                      if isinstance(m, (ast.FunctionDef, ast.AsyncFunctionDef))}
    return names


def citations() -> list[tuple[str, str, str]]:
    return [(page.relative_to(ROOT).as_posix(), m[1], m[2].lstrip(":"))
            for page in PAGES for m in CITED.finditer(page.read_text(encoding="utf-8"))]


def test_the_docs_cite_tests() -> None:
    cited = citations()
    assert len([c for c in cited if c[2]]) >= 30   # the sources table and its sections
    assert {page for page, _, _ in cited} >= {"README.md", "docs/sources.md"}


def test_every_cited_test_exists() -> None:
    missing = []
    for page, file, name in citations():
        path = ROOT / "tests" / file
        if not path.is_file():
            missing.append(f"{page}: tests/{file} (no such file)")
        elif name and name not in defined(path):
            missing.append(f"{page}: tests/{file}::{name} (no such test)")
    assert missing == []
