"""The default install stays light (issue 36): gymnasium is a default dependency and pulls no
deep-learning library; training's library is only in the optional extra [rl]."""

from __future__ import annotations

import re
from importlib.metadata import requires
from pathlib import Path

import pytest

tomllib = pytest.importorskip("tomllib")

ROOT = Path(__file__).resolve().parents[2]
HEAVY = {"torch", "tensorflow", "jax", "stable-baselines3", "stable_baselines3", "cma"}


def names(requirements: list[str]) -> set[str]:
    return {re.split(r"[\s<>=!~;\[]", r, maxsplit=1)[0].lower() for r in requirements}


def test_no_deep_learning_library_in_the_default_install() -> None:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    default = names(project["dependencies"])
    assert "gymnasium" in default and not default & HEAVY
    gym_needs = names([r for r in requires("gymnasium") or [] if "extra ==" not in r])
    assert not gym_needs & HEAVY, gym_needs
    assert names(project["optional-dependencies"]["rl"]) == {"cma"}
