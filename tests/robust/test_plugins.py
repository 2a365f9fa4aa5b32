"""Plug-in policies checked at the boundary (cell.sim.policies.check, cell.scenario.registry.load).

Whatever a policy's ``plan`` returns is checked before the cell acts on it: a NaN, a
negative or an out-of-range value in any field of the plan stops ``cell run`` with one line
naming the policy and the field (exit 2, no output folder).  A plug-in that cannot be
imported, or raises at import, when built or in ``plan``, gets one line naming it.
"""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

from cell.cli.main import main
from cell.scenario import catalog, registry
from cell.sim.policies.base import Policy
from cell.sim.policies.check import SPEEDS, TIMES, problem
from cell.sim.policies.fixed import fixed_plan
from tests.prose import in_order

FIELDS = (*TIMES, *SPEEDS, "to_g", "cycle", "limits", "steers_belts")
NAME = "robust-test-policy"
#: What the failing plug-ins of these tests say: the line must pass it on.
WHY = "no licence"


def _good(k):
    return fixed_plan(k, k.cycle_nom)


def _plain(plan, **change):
    """The plan as a bare record of its fields (read by name only), some changed."""
    return SimpleNamespace(**{**{f: getattr(plan, f) for f in FIELDS}, **change})


def _bad_values(k, field):
    """NaN, negative and out of range for ``field`` of the plan (the floors and ceilings of
    the thesis cell: the motors' fastest regime times, the belts' limits)."""
    t = k.timing
    floors = {"r1_pre": t.r1_pre.floor_s, "r1_post": t.r1_post.floor_s, "r2": t.r2_min_s,
              "r3_pre": t.r3_pre.floor_s, "r3_post": t.r3_post.floor_s, "r4": t.r4_min_s}
    if field in floors:
        return {"nan": math.nan, "negative": -1.0, "out of range": 0.5 * floors[field],
                "infinite": math.inf}
    if field in SPEEDS:
        top = k.output_max if field == "output_to_g" else k.input_max
        return {"nan": math.nan, "negative": -1.0, "out of range": 10 * top + 100}
    if field in ("to_g", "cycle"):
        return {"nan": math.nan, "negative": -1.0,
                "out of range": getattr(_good(k), field) + 1.0}
    if field == "limits":
        return {"negative": -1, "out of range": 1 << 40, "nan": math.nan}
    return {"not a boolean": "yes", "nan": math.nan}


_KINDS = {**dict.fromkeys(TIMES, ("nan", "negative", "out of range", "infinite")),
          **dict.fromkeys((*SPEEDS, "to_g", "cycle", "limits"), ("nan", "negative", "out of range")),
          "steers_belts": ("not a boolean", "nan")}
CASES = [(f, what) for f in FIELDS for what in _KINDS[f]]


class _Bad(Policy):
    """Plans what the test sets in ``change`` (a field and its value), else the fixed cycle."""

    name = NAME
    change: dict = {}

    def plan(self, view):
        return _plain(_good(self.k), **self.change)


@pytest.fixture
def bad():
    registry.register(_Bad)
    yield _Bad
    registry.unregister(NAME)
    _Bad.change = {}


def _run(tmp_path, capsys, policy=NAME):
    out = tmp_path / "out"
    code = main(["run", str(catalog.path("baseline")), "--set", "run.parts=20",
                 "--set", f"controller.policy={policy}", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    return code, err, out


@pytest.mark.parametrize("field,what", CASES)
def test_a_bad_value_in_any_field_stops_the_run_naming_policy_and_field(field, what, k):
    values = _bad_values(k, field)
    why = problem(_plain(_good(k), **{field: values[what]}), k)
    assert why is not None and why.startswith(f"{field} ="), why


def test_the_built_in_plans_pass(k):
    assert problem(_good(k), k) is None
    assert problem(_plain(_good(k)), k) is None


# one a check: a regime time, a belt command, the cycle (each field's values: the test above)
@pytest.mark.parametrize("field,value", [("r2", math.nan), ("output_to_g", 1e6), ("cycle", math.inf)])
def test_cell_run_refuses_the_plan_and_writes_nothing(bad, field, value, tmp_path, capsys):
    bad.change = {field: value}
    code, err, out = _run(tmp_path, capsys)
    assert code == 2
    assert len(err) == 1 and err[0].startswith(f"cell: error: policy {NAME!r} planned {field} =")
    assert not out.exists()
    assert os.listdir(tmp_path) == []


def test_a_plan_that_raises_is_one_line(bad, tmp_path, capsys):
    class Raises(_Bad):
        def plan(self, view):
            raise ZeroDivisionError(WHY)

    registry.register(Raises)
    code, err, out = _run(tmp_path, capsys)
    assert code == 2 and len(err) == 1
    assert in_order(err[0], f"policy {NAME!r}", f"ZeroDivisionError: {WHY}")
    assert not out.exists()


def test_a_policy_that_fails_when_built_is_one_line(bad, tmp_path, capsys):
    class Broken(_Bad):
        def __init__(self, k, controller, file=None):
            raise RuntimeError(WHY)

    registry.register(Broken)
    code, err, out = _run(tmp_path, capsys)
    assert code == 2 and len(err) == 1
    assert in_order(err[0], f"cell: error: policy {NAME!r}", "could not be built", f"RuntimeError: {WHY}")
    assert not out.exists()


# --------------------------------------------------------------------------- entry points
def _plugin_dir(tmp_path: Path, module_text: str | None) -> Path:
    """A folder that installs the entry point ``broken-plugin`` of group cell.sim.policies
    (``robustplug:Policy``), its module ``module_text`` (None: no module at all)."""
    site = tmp_path / "site"
    dist = site / "robustplug-1.0.dist-info"
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: robustplug\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text("[cell.policies]\nbroken-plugin = robustplug:Policy\n")
    if module_text is not None:
        (site / "robustplug.py").write_text(module_text)
    return site


@pytest.mark.parametrize("module,message", [
    (None, "could not be loaded (module robustplug): ModuleNotFoundError: "
           "No module named 'robustplug'"),
    ("raise RuntimeError('broken at import')\n",
     "could not be loaded: RuntimeError: broken at import"),
    ("Policy = 42\n", "is not a policy class: TypeError: int object is not callable"),
])
def test_a_plug_in_that_cannot_be_imported_is_one_line(tmp_path, monkeypatch, capsys, module,
                                                       message):
    """In-process: the folder on sys.path as PYTHONPATH would put it, the registry's entry
    points read anew (and again after the test)."""
    site = _plugin_dir(tmp_path, module)
    monkeypatch.syspath_prepend(str(site))
    monkeypatch.setattr(registry, "_entry_points", None)
    monkeypatch.delitem(sys.modules, "robustplug", raising=False)
    out = tmp_path / "out"
    try:
        code = main(["run", str(catalog.path("baseline")), "--set", "run.parts=5",
                     "--set", "controller.policy=broken-plugin", "--out", str(out)])
    finally:
        sys.modules.pop("robustplug", None)
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.splitlines() == [f"cell: error: policy 'broken-plugin' {message}"]
    assert not out.exists()


def test_a_sweep_of_a_bad_plug_in_is_one_line_and_leaves_no_folder(bad, tmp_path, capsys):
    bad.change = {"input_next": math.nan}
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(f"base: {catalog.path('baseline')}\nset: {{run.parts: 20}}\n"
                     f"policies: [{NAME}]\nreplications: 2\n")
    out = tmp_path / "out"
    code = main(["sweep", str(sweep), "--out", str(out), "--workers", "1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and err[-1].startswith("cell: error: ")
    assert in_order(err[-1], f"policy {NAME!r}", "planned input_next = nan", "not finite")
    assert os.listdir(tmp_path) == ["sweep.yaml"]
