"""The house shows the model (issue 20): folders by concern, every module listed in
docs/architecture.md and in the README's layout, no two modules of one name, ``__init__.py``
files that only re-export, modules and functions small enough to read, and an import
contract written by folder."""

from __future__ import annotations

import ast
import functools
import re
from pathlib import Path

import pytest

tomllib = pytest.importorskip("tomllib")

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "cell"
FOLDERS = ("cli", "reporting", "bench", "experiments", "rl", "sim", "scenario", "arm", "plumbing")


def modules() -> list[Path]:
    return [p.relative_to(PACKAGE) for p in sorted(PACKAGE.rglob("*.py"))
            if p.name != "__init__.py"]


@functools.cache
def sources() -> dict[Path, tuple[str, ast.Module]]:
    """Every module of the package, its text and its tree, read and parsed once for the tests
    that walk them all."""
    out = {}
    for p in sorted(PACKAGE.rglob("*.py")):
        src = p.read_text(encoding="utf-8")
        out[p] = (src, ast.parse(src))
    return out


def test_architecture_lists_every_module() -> None:
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    missing = [m.as_posix() for m in modules() if f"`{m.as_posix()}`" not in text]
    assert missing == []


def test_readme_layout_lists_every_module() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    layout = readme.split("## Layout", 1)[1].split("\n## ", 1)[0]
    lines: dict[str, str] = {}
    folder = ""
    for line in layout.splitlines():
        m = re.match(r"  (\S+/)\s+(.*)", line)
        if m:
            folder = m.group(1)
            lines[folder] = m.group(2)
        elif folder and line.startswith(" " * 20):
            lines[folder] += " " + line.strip()
    missing = []
    for m in modules():
        if len(m.parts) == 1:
            continue  # the package's own __main__.py
        where = "/".join(m.parts[:-1]) + "/"
        names = re.split(r"[,\s]+", lines.get(where, ""))
        if m.stem not in names:
            missing.append(m.as_posix())
    assert missing == []


def test_the_top_level_holds_only_the_folders() -> None:
    top = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert top == ["__init__.py", "__main__.py"]
    for folder in FOLDERS:
        assert (PACKAGE / folder / "__init__.py").is_file(), folder


def test_no_two_modules_share_a_name() -> None:
    """Apart from a command's own module in cli/, named after the command (cli/fit.py runs
    ``cell fit``, whose work is experiments/fit/)."""
    from cell.cli.parser import COMMANDS

    seen: dict[str, str] = {}
    twice = []
    for m in modules():
        if m.name == "__main__.py" or (m.parts[0] == "cli" and m.stem in COMMANDS):
            continue
        if m.name in seen:
            twice.append((seen[m.name], m.as_posix()))
        seen[m.name] = m.as_posix()
    assert twice == []


def test_init_files_only_re_export() -> None:
    logic = []
    for init in sorted(PACKAGE.rglob("__init__.py")):
        for node in ast.parse(init.read_text(encoding="utf-8")).body:
            plain = isinstance(node, (ast.Import, ast.ImportFrom)) or (
                isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant))
            names = isinstance(node, ast.Assign) and all(
                isinstance(t, ast.Name) and t.id in ("__all__", "__version__") for t in node.targets)
            if not (plain or names):
                logic.append(f"{init.relative_to(ROOT)}:{node.lineno}")
    assert logic == []


def test_modules_and_functions_are_small() -> None:
    big = []
    for p, (src, tree) in sources().items():
        if src.count("\n") > 400:
            big.append(f"{p.relative_to(ROOT)}: {src.count(chr(10))} lines")
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = (node.end_lineno or node.lineno) - node.lineno + 1
                if n > 60:
                    big.append(f"{p.relative_to(ROOT)}:{node.lineno} {node.name}: {n} lines")
    assert big == []


def test_the_import_contract_is_written_by_folder() -> None:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    layers = config["tool"]["importlinter"]["contracts"][0]["layers"]
    named = [name.strip() for layer in layers for name in layer.split("|")]
    assert sorted(named) == sorted(f"cell.{f}" for f in FOLDERS)


def private_imports(tree: ast.AST) -> list[tuple[int, str]]:
    """``from cell... import _name`` in a module's tree (a dunder such as ``__version__``
    is public), as (line, name)."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module and (
                node.module == "cell" or node.module.startswith("cell.")):
            found += [(node.lineno, a.name) for a in node.names
                      if a.name.startswith("_") and not a.name.startswith("__")]
        if isinstance(node, ast.ImportFrom) and node.level > 0:
            found += [(node.lineno, a.name) for a in node.names
                      if a.name.startswith("_") and not a.name.startswith("__")]
    return found


def test_the_private_import_check_sees_one() -> None:
    tree = ast.parse("from cell.x import a, _b, __version__\nfrom .y import _c\n"
                     "def f():\n    from cell.z import _d\n")
    assert sorted(private_imports(tree)) == [(1, "_b"), (2, "_c"), (4, "_d")]


def test_no_module_imports_a_private_name() -> None:
    private = []
    for p, (_, tree) in sources().items():
        private += [f"{p.relative_to(ROOT)}:{line} {name}" for line, name in private_imports(tree)]
    assert private == []


def test_command_line_modules_parse_and_print() -> None:
    """cli/ parses and prints: its modules stay short, what they print made below them."""
    long = [f"{p.relative_to(ROOT)}: {p.read_text(encoding='utf-8').count(chr(10))} lines"
            for p in sorted((PACKAGE / "cli").glob("*.py"))
            if p.read_text(encoding="utf-8").count("\n") > 200]
    assert long == []


def test_command_modules_are_named_after_their_command() -> None:
    from cell.cli.parser import COMMANDS

    cli = {p.stem for p in (PACKAGE / "cli").glob("*.py")}
    assert set(COMMANDS) <= cli
    assert sorted(n for n in cli if n.endswith("_command")) == []
