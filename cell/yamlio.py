"""Reading YAML that users write (placeholder: the hardened reader replaces this)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from cell.errors import ScenarioError


def load_mapping(path: str | Path, what: str = "scenario") -> dict[str, Any]:
    """A YAML file's top-level mapping (an empty file is an empty mapping)."""
    path = Path(path)
    if not path.is_file():
        raise ScenarioError(path, "(file)", str(path), f"no such {what} file")
    try:
        raw = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise ScenarioError(path, "(file)", str(path), f"not valid YAML: {exc}") from None
    raw = {} if raw is None else raw
    if not isinstance(raw, dict):
        raise ScenarioError(path, "(top level)", raw, "must be a mapping of keys")
    return raw


def parse_value(text: str, origin: str = "--set") -> Any:
    """One YAML value from the command line."""
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ScenarioError(origin, origin, text, f"not valid YAML: {exc}") from None
