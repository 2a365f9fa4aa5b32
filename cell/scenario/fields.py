"""The schema's building blocks, shared by scenario and model files.

Sections are pydantic models (unknown keys refused, frozen once read, attribute
docstrings as the JSON Schema's descriptions); :func:`error_from_validation`
turns pydantic's report into the one line a user reads: file, dotted key,
value, and what is wrong, in plain words.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, ValidationError

from cell.plumbing.errors import ScenarioError


class Section(BaseModel):
    """A section of a file: unknown keys refused, values frozen once read."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True,
                              validate_default=False)


#: pydantic error types -> the phrase a user reads.
_PHRASES = {
    "float_type": "must be a number", "finite_number": "must be a finite number",
    "int_type": "must be a whole number", "bool_type": "must be true or false",
    "string_type": "must be text", "dict_type": "must be a mapping",
    "model_type": "must be a mapping of keys", "model_attributes_type": "must be a mapping of keys",
    "tuple_type": "must be a list", "int_from_float": "must be a whole number",
}


def error_from_validation(exc: ValidationError, raw: Any, file: object,
                          root: type[BaseModel]) -> ScenarioError:
    """The first problem pydantic found, as one line naming file, dotted key and value."""
    err = exc.errors()[0]
    loc = [p for p in err["loc"] if not (isinstance(p, str) and p.startswith("function-"))]
    kind, ctx = err["type"], err.get("ctx") or {}
    tuple_index = None
    # a wrong-length list is reported on its missing or extra item: name the list itself
    if kind in ("missing", "too_long", "too_short") and loc and isinstance(loc[-1], int):
        tuple_index = loc.pop()
    key = ".".join(f"[{p}]" if isinstance(p, int) else str(p) for p in loc).replace(".[", "[")
    value = _lookup(raw, loc)
    if kind == "extra_forbidden":
        why = "unknown key (known: " + ", ".join(_fields_at(root, loc[:-1])) + ")"
    elif kind in ("missing", "too_long", "too_short") and tuple_index is not None or \
            kind in ("too_long", "too_short"):
        n = len(_default_at(root, loc) or ())
        why = f"must have exactly {n} entries"
    elif kind in ("greater_than", "greater_than_equal", "less_than_equal", "less_than"):
        limit = ctx.get("gt", ctx.get("ge", ctx.get("le", ctx.get("lt"))))
        word = {"greater_than": "greater than", "greater_than_equal": "at least",
                "less_than_equal": "at most", "less_than": "less than"}[kind]
        why = f"must be {word} {limit:g}" if isinstance(limit, (int, float)) and \
            abs(limit) < 1e15 else f"must be {word} {limit}"
    elif kind == "literal_error":
        why = "must be one of " + str(ctx.get("expected", "")).replace("'", "")
    elif kind == "value_error":
        why = str(ctx.get("error", err["msg"]))
    else:
        why = _PHRASES.get(kind, err["msg"][0].lower() + err["msg"][1:]) + write_instead(kind, value)
    return ScenarioError(file, key or "(top level)", value, why)


def write_instead(kind: str, value: Any) -> str:
    """What to write where a value was plainly meant but has the wrong type: a count written
    as a float (1e3), text that YAML read as a number (``name: 2026``).  Counts stay strict, as
    every int setting is: a float is not silently taken for one."""
    exact = isinstance(value, float) and value.is_integer() and abs(value) < 2.0 ** 53
    if kind in ("int_type", "int_from_float") and exact:
        return f"; write {int(value)}"
    if kind == "string_type" and isinstance(value, (int, float)) and not isinstance(value, bool):
        return f"; quote it: '{value}'"
    return ""


def _lookup(raw: Any, loc: list[Any]) -> Any:
    node = raw
    for p in loc:
        try:
            node = node[p]
        except (KeyError, IndexError, TypeError):
            return None
    return node


def model_at(root: type[BaseModel], loc: list[Any]) -> type[BaseModel] | None:
    """The section model at a key path, or None if the path is not a section."""
    model: Any = root
    for p in loc:
        field = model.model_fields.get(p) if isinstance(p, str) else None
        annotation = unwrap_optional(field.annotation) if field is not None else None
        if field is None or not (isinstance(annotation, type)
                                 and issubclass(annotation, BaseModel)):
            return None
        model = annotation
    return model


def unwrap_optional(annotation: Any) -> Any:
    """``Model | None`` (an optional section, such as ``failures``) as ``Model``."""
    args = getattr(annotation, "__args__", None)
    if args and len(args) == 2 and type(None) in args and getattr(annotation, "__origin__", None) \
            is not dict:
        other = args[0] if args[1] is type(None) else args[1]
        if isinstance(other, type) and issubclass(other, BaseModel):
            return other
    return annotation


def _fields_at(root: type[BaseModel], loc: list[Any]) -> list[str]:
    model = model_at(root, loc)
    return list(model.model_fields) if model is not None else []


def _default_at(root: type[BaseModel], loc: list[Any]) -> Any:
    model = model_at(root, loc[:-1])
    if model is None or not loc:
        return None
    field = model.model_fields.get(loc[-1])
    return None if field is None else field.get_default(call_default_factory=True)
