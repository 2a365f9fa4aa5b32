"""The built-in scenarios, shipped inside the package (``cell/scenarios/``).

A command's SCENARIO argument is a file path or a built-in name: ``cell run
baseline`` works from any directory and after a normal install.  ``cell
scenarios`` lists them with their one-line descriptions.
"""

from __future__ import annotations

from pathlib import Path

#: The folder of the built-in scenario and sweep files.
BUILT_IN = Path(__file__).resolve().parent / "scenarios"


def path(name: str) -> Path:
    """A built-in file by name (``baseline`` or ``baseline.yaml``)."""
    stem = name[:-5] if name.endswith(".yaml") else name
    return BUILT_IN / f"{stem}.yaml"


def resolve(name_or_path: str | Path) -> Path:
    """A SCENARIO argument as a file: an existing path as given, else a built-in name."""
    given = Path(name_or_path)
    if given.exists() or given.suffix and given.parent != Path("."):
        return given
    built_in = path(str(name_or_path))
    return built_in if built_in.is_file() else given


def names() -> list[str]:
    """Every built-in file's name, without ``.yaml``."""
    return sorted(p.stem for p in BUILT_IN.glob("*.yaml"))


def describe(name: str) -> str:
    """A built-in file's ``description``, or its first comment line."""
    import yaml

    text = path(name).read_text(encoding="utf-8")
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError:  # pragma: no cover - the files are the project's own
        doc = None
    if isinstance(doc, dict) and doc.get("description"):
        return str(doc["description"])
    first = next((line for line in text.splitlines() if line.startswith("#")), "# ")
    return first.lstrip("# ").strip()
