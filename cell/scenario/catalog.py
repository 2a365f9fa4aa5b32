"""The built-in scenarios, shipped inside the package (``cell/scenarios/``).

A command's SCENARIO argument is a file path or a built-in name: ``cell run
baseline`` works from any directory and after a normal install.  ``cell
scenarios`` lists them with their one-line descriptions.
"""

from __future__ import annotations

import os
from pathlib import Path

#: The folder of the built-in scenario and sweep files.
BUILT_IN = Path(__file__).resolve().parent.parent / "scenarios"


#: What separates folders in a path as a user may type it.
_SEPARATORS = frozenset({"/", os.sep} | ({os.altsep} if os.altsep else set()))


def path(name: str) -> Path:
    """A built-in file by name (``baseline`` or ``baseline.yaml``)."""
    stem = name[:-5] if name.endswith(".yaml") else name
    return BUILT_IN / f"{stem}.yaml"


def resolve(name_or_path: str | Path, beside: Path | None = None) -> Path:
    """A SCENARIO argument as a file: an existing path as given, else a built-in name.
    ``beside``: the folder a relative path is taken from (by default the working
    directory), as a sweep file's ``base`` is from the sweep file's.  Only a plain name
    (no folder in it) may be a built-in one: ``../scenarios/baseline`` that is not there
    is a missing file, not the built-in baseline."""
    given = Path(name_or_path)
    here = given if beside is None else beside / given
    if here.exists() or any(sep in str(name_or_path) for sep in _SEPARATORS):
        return here
    built_in = path(str(name_or_path))
    return built_in if built_in.is_file() else here


#: Keys only a sweep file has, and keys only a dynamics file has.
SWEEP_ONLY = frozenset({"base", "grid", "policies", "replications", "baseline", "batch", "set"})
DYNAMICS_ONLY = frozenset({"links", "drives", "gravity_m_s2"})
STUDY_ONLY = frozenset({"vary", "objectives", "constraints", "trials", "morris", "sobol"})

#: What each kind of file is for, for messages.
USE = {"scenario": "run it with `cell run`, `cell compare` or `cell animate`",
       "sweep": "run it with `cell sweep`",
       "dynamics": "name it in a scenario's mintime.dynamics_file",
       "study": "run it with `cell optimize` or `cell sensitivity`"}


def kind(raw: object) -> str:
    """``scenario``, ``sweep`` or ``dynamics``: what a file's top-level mapping is, by its keys."""
    keys = set(raw) if isinstance(raw, dict) else set()
    if keys & DYNAMICS_ONLY:
        return "dynamics"
    if keys & STUDY_ONLY:
        return "study"
    if keys & SWEEP_ONLY:
        return "sweep"
    return "scenario"


def refuse_other_kind(raw: object, path: Path | str, wanted: str) -> None:
    """Raise a one-line error when a ``wanted`` file is really another kind of file."""
    from cell.plumbing.errors import ScenarioError

    found = kind(raw)
    if found != wanted:
        raise ScenarioError(path, "(file)", str(path), f"this is a {found} file, not a {wanted} "
                            f"file: {USE[found]}")


def shown(source: str | Path) -> str:
    """How to name a file in a command line: a built-in one by its name, any other as given."""
    p = Path(source)
    try:
        inside = p.resolve().parent == BUILT_IN and p.suffix == ".yaml"
    except OSError:
        inside = False
    return p.stem if inside and p.is_absolute() else str(source)


def names() -> list[str]:
    """Every built-in file's name, without ``.yaml``."""
    return sorted(p.stem for p in BUILT_IN.glob("*.yaml"))
