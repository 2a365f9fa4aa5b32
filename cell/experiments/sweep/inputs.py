"""The files a sweep reads, by content: its sweep file, its base scenario and every file
its points' scenarios name (:data:`cell.scenario.schema.PATH_KEYS`: the arrivals trace, the
dynamics model).  The named files' content is part of the sweep's fingerprint (a trace
edited between a run and its ``--resume`` changes the results as an edited YAML does);
the digests of all of them go into ``sweep.json``, to say which file changed when a
resume is refused."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path
from typing import TYPE_CHECKING

from cell.plumbing.errors import ScenarioError
from cell.scenario.schema import PATH_KEYS

if TYPE_CHECKING:
    from cell.experiments.sweep.spec import Sweep
    from cell.scenario.schema import Scenario


def digest(path: str | Path) -> str | None:
    """SHA-256 of a file's bytes; None if it cannot be read."""
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError:
        return None


def named_files(scenario: Scenario) -> list[Path]:
    """The files a scenario names (its trace, its dynamics model), where they are read from."""
    from cell.sim.scenario_values import dynamics_path

    found: list[Path] = []
    for section, key in PATH_KEYS:
        if getattr(getattr(scenario, section), key) is None:
            continue
        if (section, key) == ("mintime", "dynamics_file"):
            try:  # beside the scenario, else the built-in one of that name
                path = dynamics_path(scenario)
            except ScenarioError:  # not there: the run says so, if it needs it
                continue
            found += [path] if path is not None else []
        else:
            found.append(scenario.base_dir / getattr(getattr(scenario, section), key))
    return found


def sweep_files(sweep: Sweep) -> list[Path]:
    """Every file the points' scenarios name, each once, resolved, in a fixed order."""
    paths = {p.resolve() for point in sweep.points for p in named_files(point.scenario)}
    return sorted(paths)


def inputs(sweep: Sweep) -> dict[str, str | None]:
    """Every file the sweep reads (the sweep file, the base scenario, the files they name),
    resolved, with its digest."""
    files = [Path(f) for f in (sweep.source, sweep.base.source) if Path(f).is_file()]
    paths = dict.fromkeys([*(f.resolve() for f in files), *sweep_files(sweep)])
    return {str(p): digest(p) for p in paths}


def changed(recorded: object) -> list[str]:
    """The files of a manifest's ``inputs`` whose content differs now (or that are gone),
    as paths from here where they are below it."""
    if not isinstance(recorded, dict):
        return []
    return [_shown(path) for path, was in recorded.items() if digest(path) != was]


def _shown(path: str) -> str:
    try:
        here = os.path.relpath(path)
    except ValueError:  # another drive
        return path
    return path if here.startswith("..") else here
