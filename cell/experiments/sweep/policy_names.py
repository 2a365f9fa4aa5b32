"""A sweep's ``policies:``: each policy named once (kept apart from :mod:`cell.experiments.sweep.spec`,
which reads the rest of the sweep file)."""

from __future__ import annotations

from typing import Any

from cell.plumbing.errors import ScenarioError
from cell.scenario import registry


def check_policy_names(policies: Any, path: object) -> None:
    """A sweep's ``policies:`` names each policy once, by a name: a list or a mapping inside
    it, or a name listed twice, is one line (``policies[i]``) rather than a traceback or a
    policy run twice over."""
    names = list(policies) if isinstance(policies, (list, dict)) else []
    seen: set[str] = set()
    for i, name in enumerate(names):
        key = f"policies[{i}]" if isinstance(policies, list) else "policies"
        if not isinstance(name, str) or not name:
            raise ScenarioError(path, key, name, "must be a policy's name (one of "
                                + ", ".join(registry.names()) + ")")
        if name in seen:
            raise ScenarioError(path, key, name, "listed twice: list each policy once")
        seen.add(name)
