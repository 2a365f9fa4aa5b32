"""Every scenario key, walked from the schema, given hostile values through ``--set`` and files.

For each setting of :class:`cell.scenario.schema.Scenario` the generator derives its type and bounds
from the pydantic fields and produces values of two kinds: those the schema itself forbids
(wrong type, booleans for numbers, text, lists, mappings, null, ±inf, nan, 1e300, beyond a
bound, integers of 39 and 45 digits), which must be refused in one line naming the key; and
values inside the bounds (the bounds themselves, 1e-300 above an open one, halves, doubles,
integers for floats), which must either be refused in one line naming the key (the physics
may forbid them) or run sanely.
"""

from __future__ import annotations

import math
import typing
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from annotated_types import Ge, Gt, Le, Lt
from pydantic import BaseModel

from cell.scenario.schema import Scenario, default_scenario

from .harness import cli, ran_sanely, refused

PARTS = 6
DEFAULTS = default_scenario()
#: The baseline cell in two lines (its every other value is the built-in default, as
#: cell/scenarios/baseline.yaml says): ``--set`` cases on it meet the same rules as on
#: ``baseline``, where reading that 113-line file anew was most of a refused case's time.
BASE = "name: baseline\ncontroller: {nominal_cycle_s: 22.5872}\n"


def yaml_text(value: Any) -> str:
    """A value written as YAML 1.2 flow text (what a user would type)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "null"
    if isinstance(value, float):
        return ".nan" if math.isnan(value) else (".inf" if value > 0 else "-.inf") if math.isinf(value) \
            else repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list):
        return "[" + ", ".join(yaml_text(v) for v in value) + "]"
    return "{" + ", ".join(f"{k}: {yaml_text(v)}" for k, v in value.items()) + "}"


@dataclass(frozen=True)
class Bounds:
    lo: float | None = None
    lo_open: bool = False
    hi: float | None = None
    hi_open: bool = False

    def inside(self, x: float) -> bool:
        return ((self.lo is None or (x > self.lo if self.lo_open else x >= self.lo))
                and (self.hi is None or (x < self.hi if self.hi_open else x <= self.hi)))


def bounds_of(metadata: list[Any]) -> Bounds:
    b: dict[str, Any] = {}
    for m in metadata:
        if isinstance(m, (Gt, Ge)):
            b.update(lo=float(m.gt if isinstance(m, Gt) else m.ge), lo_open=isinstance(m, Gt))
        elif isinstance(m, (Lt, Le)):
            b.update(hi=float(m.lt if isinstance(m, Lt) else m.le), hi_open=isinstance(m, Lt))
    return Bounds(**b)


def leaves(model: type[BaseModel], prefix: str = "") -> Iterator[tuple[str, Any, Any]]:
    """(dotted key, annotation, field) of every setting, sections walked."""
    for name, field in model.model_fields.items():
        ann = field.annotation
        if isinstance(ann, type) and issubclass(ann, BaseModel):
            yield from leaves(ann, f"{prefix}{name}.")
        else:
            yield prefix + name, ann, field


#: One value per rule of a number's type: a boolean is not a number (``false`` would test the
#: same rule again), nor text, nor text that reads as one (no coercion), nor a list, nor a mapping.
WRONG_TYPES: list[tuple[str, Any]] = [("true", True), ("text", "x"), ("numeric-text", "1.5"),
                                      ("list", [1.0]), ("mapping", {"a": 1.0})]


Values = list[tuple[str, Any]]


def number_values(b: Bounds, default: float, whole: bool) -> tuple[Values, Values]:
    """(refuse, either) values for a number with bounds ``b``: one refused value per rule (the
    type's, finiteness, YAML's integer digits, each bound; a huge value only where no bound
    stands in the way, as it would test the bound's rule again)."""
    refuse = list(WRONG_TYPES) + [("inf", math.inf), ("nan", math.nan), ("45-digit int", 10**45)]
    either: list[tuple[str, Any]] = []
    if b.hi is None:
        refuse.append(("1e300", 1e300))
    if b.lo is None:
        refuse.append(("-1e300", -1e300))
    if whole:
        refuse += [("1.5", 1.5), ("2.0", 2.0), ("sexagesimal", "1:30")]
    step = 1 if whole else max(1.0, abs(b.lo or 0) * 0.01)
    if b.lo is not None:
        refuse.append(("below", b.lo - step if not b.lo_open else b.lo))
        if b.lo_open:  # just above an open bound (1e-9 above: the same rule)
            either.append(("1e-300 above", b.lo + 1e-300 if b.lo == 0 else b.lo * (1 + 1e-12)))
        else:
            either.append(("lowest", int(b.lo) if whole else b.lo))
    if b.hi is not None:
        refuse.append(("above", b.hi + (1 if whole else max(1.0, abs(b.hi) * 0.01)) if not b.hi_open
                       else b.hi))
        either.append(("highest", (int(b.hi) - int(b.hi_open)) if whole else b.hi))
    for label, factor in (("half", 0.5), ("double", 2.0), ("x1000", 1e3)):
        x = default * factor
        x = round(x) if whole else x
        if b.inside(x) and x != default:
            either.append((label, x))
    if not whole and float(default).is_integer():
        either.append(("as int", int(default)))
    return refuse, either


#: Accepted values that would make a case slow (a run of 10⁷ parts), replaced by a smaller one.
SLOW = {("run.parts", "highest"), ("run.parts", "x1000")}


def cases() -> Iterator[Any]:
    for key, ann, field in leaves(Scenario):
        default = DEFAULTS.get(key)
        origin, args = typing.get_origin(ann), typing.get_args(ann)
        optional = origin is not None and type(None) in args
        refuse: list[tuple[str, Any]]
        either: list[tuple[str, Any]] = []
        if ann in (float, int) or optional and float in args:
            whole = ann is int
            refuse, either = number_values(bounds_of(field.metadata), default or 100.0, whole)
            if optional:
                either.append(("null", None))
            else:
                refuse.append(("null", None))
        elif ann is bool:
            # an integer is not a boolean (0 is 1's rule), nor a word (a quoted "true" is yes's)
            refuse = [("1", 1), ("null", None), ("yes", "yes"), ("list", [True])]
            either = [("true", True), ("false", False)]
        elif origin is tuple:
            n = len(args)
            element = bounds_of(typing.get_args(args[0])[1].metadata)
            el_refuse, el_either = number_values(element, default[0] or 1.0, whole=False)
            refuse = [("too short", list(default[:-1])), ("too long", [*default, default[0]]),
                      ("empty", []), ("text", "x"), ("null", None), ("mapping", {"a": 1}),
                      ("nested", [list(default)] + list(default[1:]))]
            # each element's rules on the first one (the same rules on all of them: no new rule)
            refuse += [(f"[0] {label}", [v, *default[1:]]) for label, v in el_refuse]
            either = [(f"[0] {label}", [v, *default[1:]]) for label, v in el_either]
            either += [(f"all {label}", [v] * n) for label, v in el_either]
        elif origin is not None and any(typing.get_origin(a) is typing.Literal for a in args):
            # a number or a word (run.warmup_parts: 4 or auto)
            number = next(a for a in args if typing.get_origin(a) is typing.Annotated)
            word = next(a for a in args if typing.get_origin(a) is typing.Literal)
            refuse, either = number_values(bounds_of(typing.get_args(number)[1].metadata), 1.0, whole=True)
            refuse = [(label, v) for label, v in refuse if label not in ("text",)] + [
                ("other word", "bogus"), ("word in capitals", str(typing.get_args(word)[0]).upper()),
                ("null", None)]
            either = [(label, v) for label, v in either if label != "highest"]
            either += [(w, w) for w in typing.get_args(word)] + [("some", 3)]
        elif origin is typing.Literal:
            # a word not among the choices ("" is bogus's rule), a number, null, a list
            refuse = [("bogus", "bogus"), ("null", None), ("number", 1), ("list", list(args))]
            either = [(v, v) for v in args if v != default]
        elif ann is str:
            # a number is not text (1.5 is 1's rule), nor a boolean, null, a list, a mapping
            refuse = [("number", 1), ("null", None), ("true", True), ("mapping", {"a": "b"}),
                      ("list", ["a"])]
            if key in ("name", "description"):
                either = [("empty", ""), ("long", "n" * 5000), ("unicode", "ünïcødé ✓ 工作单元"),
                          ("tab", "a\tb"), ("quote and comma", 'a "b", c')]
            else:
                refuse += [("bogus", "bogus"), ("empty", ""), ("dunder", "__class__")]
        else:  # arrivals.params, trace_csv, dynamics_file: tables of their own (test_hostile_files)
            refuse = [("number", 1), ("true", True), ("list", [1])] if origin is dict else \
                [("number", 1), ("true", True), ("list", ["a"]), ("mapping", {"a": "b"})]
        for label, value in refuse:
            yield Case(key, label, value, True)
        for label, value in either:
            yield Case(key, label, 40 if (key, label) in SLOW else value, False)


@dataclass(frozen=True)
class Case:
    key: str
    label: str
    value: Any
    must_refuse: bool
    """True: the schema forbids it; False: refused in one line or a sane run."""


KEYS = [key for key, _, _ in leaves(Scenario)]
CASES = list(cases())



def _parts(key: str, value: Any) -> int:
    return value if key == "run.parts" and isinstance(value, int) and not isinstance(value, bool) else PARTS


def _check_set(tmp: Path, case: Case) -> None:
    """``cell run baseline --set KEY=VALUE``: refused in one line naming the key, or a sane run."""
    out = tmp / f"out-{abs(hash((case.key, case.label)))}"
    res = cli("run", tmp / "base.yaml", "--set", f"run.parts={PARTS}", "--set",
               f"{case.key}={yaml_text(case.value)}", "--out", out)
    if case.must_refuse:
        refused(res, case.key, nothing_in=out)
    elif res.code != 0:  # the physics may refuse it; the line names the key it is about
        line = refused(res, "base.yaml", nothing_in=out)
        assert any(k in line for k in KEYS), line
    else:
        ran_sanely(res, out, _parts(case.key, case.value))


def _check_file(tmp: Path, case: Case) -> None:
    """The value written in a scenario file: refused in one line naming the file and the key."""
    scenario = tmp / "hostile.yaml"
    doc = _nested(case.key, case.value)
    doc.setdefault("run", {})["parts"] = doc.get("run", {}).get("parts", PARTS)
    scenario.write_text("\n".join(f"{k}: {yaml_text(v)}" for k, v in doc.items()) + "\n", encoding="utf-8")
    out = tmp / "out"
    refused(cli("run", scenario, "--out", out), str(scenario), case.key, nothing_in=out)


def _nested(key: str, value: Any) -> dict[str, Any]:
    doc: dict[str, Any] = {}
    node = doc
    *sections, leaf = key.split(".")
    for part in sections:
        node = node.setdefault(part, {})
    node[leaf] = value
    return doc


def _all(tmp: Path, check: Any, cases: list[Case]) -> None:
    """Every case checked; the failures reported together."""
    failures = []
    for case in cases:
        try:
            check(tmp, case)
        except AssertionError as exc:
            failures.append(f"{case.key} = {case.label} ({yaml_text(case.value)[:60]}): {exc}"[:1500])
    assert not failures, f"{len(failures)} of {len(cases)} cases broke the promise:\n" + "\n".join(failures)


@pytest.mark.parametrize("key", KEYS)
def test_set_on_the_command_line(tmp_path: Path, key: str) -> None:
    """Each key's hostile values given with ``--set``."""
    (tmp_path / "base.yaml").write_text(BASE)
    _all(tmp_path, _check_set, [c for c in CASES if c.key == key])


@pytest.mark.parametrize("key", KEYS)
def test_in_a_scenario_file(tmp_path: Path, key: str) -> None:
    """Each key's forbidden values (every other one, in the order listed) written in a scenario
    file."""
    _all(tmp_path, _check_file, [c for c in CASES if c.key == key and c.must_refuse][::2])


def test_the_walk_covers_every_setting() -> None:
    """Each leaf of the schema has refused cases, and the numeric ones accepted cases too."""
    keys = {key for key, _, _ in leaves(Scenario)}
    assert len(keys) >= 55
    assert keys == {c.key for c in CASES} == set(KEYS)
    numeric = {key for key, ann, _ in leaves(Scenario) if ann in (float, int)}
    assert numeric <= {c.key for c in CASES if not c.must_refuse}
