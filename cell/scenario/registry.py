"""The control policies the cell knows, by name.

A policy is a class implementing :class:`cell.sim.policies.Policy`.  The two of the
thesis are built in (``non-adaptive``, §6.3, and ``adaptive``, §5.3); another is
added with :func:`register` (in-process, e.g. from a test or a notebook) or by a
package that declares an entry point in the group ``cell.sim.policies``.  The names
feed the scenario's allowed values of ``controller.policy`` and a sweep's
policy list.  Built-ins are imported only when used, so reading a scenario does
not load the simulation.
"""

from __future__ import annotations

import importlib
from typing import Any

from cell.plumbing.errors import CellError, ScenarioError, one_line
from cell.plumbing.interrupts import interrupted

#: Built-in policies: name -> "module:Class", imported on first use.
BUILT_IN: dict[str, str] = {
    "non-adaptive": "cell.sim.policies.fixed:FixedCycle",
    "adaptive": "cell.sim.policies.adaptive:Adaptive",
}
ENTRY_POINT_GROUP = "cell.policies"

_registered: dict[str, Any] = {}
_entry_points: dict[str, Any] | None = None


class PluginError(CellError):
    """A policy that cannot be loaded or built: one line naming it and its error (a plain
    message, so it crosses to and from a sweep's worker processes intact)."""

    @classmethod
    def of(cls, name: str, what: str, exc: BaseException) -> PluginError:
        module = getattr(exc, "name", None) if isinstance(exc, ImportError) else None
        where = f" (module {module})" if module else ""
        return cls(f"policy {name!r} {what}{where}: {type(exc).__name__}: "
                   f"{one_line(str(exc) or '(no message)', 200)}")


def _plugins() -> dict[str, Any]:
    global _entry_points
    if _entry_points is None:
        from importlib.metadata import entry_points

        try:
            _entry_points = {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP)}
        except Exception:  # noqa: BLE001 - a broken installed distribution: no plug-ins
            _entry_points = {}
    return _entry_points


def register(policy: Any, name: str | None = None) -> Any:
    """Make a policy class known under ``name`` (default: its ``name`` attribute).

    Usable as a class decorator.  Registering a name twice replaces the first.
    """
    key = name or getattr(policy, "name", None)
    if not isinstance(key, str) or not key:
        raise ValueError("a policy needs a non-empty name")
    _registered[key] = policy
    return policy


def unregister(name: str) -> None:
    _registered.pop(name, None)


def names() -> tuple[str, ...]:
    """Every known policy name: the built-ins, then registered ones, then plug-ins."""
    return tuple(dict.fromkeys([*BUILT_IN, *_registered, *_plugins()]))


def known(name: str) -> bool:
    """Whether a policy of that name exists (installed plug-ins looked up only if it is not
    built in or registered: a scan of the installed packages, once a process)."""
    return name in BUILT_IN or name in _registered or name in _plugins()


def get(name: str) -> Any:
    """The policy class registered as ``name`` (KeyError if there is none)."""
    if name in _registered:
        return _registered[name]
    if name in BUILT_IN:
        module, _, cls = BUILT_IN[name].partition(":")
        return getattr(importlib.import_module(module), cls)
    if name in _plugins():
        return _plugins()[name].load()
    raise KeyError(name)


def load(name: str, source: object = None) -> Any:
    """:func:`get`, every failure one line: a name that is not known is the scenario's
    ``controller.policy`` error (``source``, the scenario's file); a plug-in that cannot be
    imported, raises while it is, or is not a policy class, a :class:`PluginError`."""
    try:
        cls = get(name)
    except KeyError:
        raise ScenarioError(source, "controller.policy", name,
                            "must be one of " + ", ".join(names())) from None
    except CellError:
        raise
    except Exception as exc:  # noqa: BLE001 - a plug-in's own failure, named
        if interrupted(exc):  # an import that Ctrl-C cut short
            raise
        raise PluginError.of(name, "could not be loaded", exc) from exc
    if not callable(cls):
        raise PluginError.of(name, "is not a policy class",
                             TypeError(f"{type(cls).__name__} object is not callable"))
    return cls
