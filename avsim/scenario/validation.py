"""Validation against the format's models, and its errors in the one-line form.

`validate` checks a file's data (overrides applied) against `ScenarioModel` and raises the
first problem as a `LocatedError`: pydantic's location becomes the file's key path (the
names pydantic adds for union members are dropped), its error a short message
(`must be > 0, got -5`, `unknown key (did you mean speed_kph?)`). A problem at or below a
key an override set says so: `(set by an override)`.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Mapping, Sequence
from typing import Any, TypeVar, get_args

from pydantic import BaseModel, ValidationError
from pydantic_core import ErrorDetails

from avsim.scenario.errors import KeyPath, LocatedError, dotted, fmt, show
from avsim.scenario.model import ScenarioModel

_EXPECTED = {
    "float_type": "a number",
    "float_parsing": "a number",
    "int_type": "an integer",
    "int_from_float": "an integer",
    "int_parsing": "an integer",
    "string_type": "a string",
    "bool_type": "true or false",
    "model_type": "a mapping (key: value)",
    "model_attributes_type": "a mapping (key: value)",
    "dict_type": "a mapping (key: value)",
    "list_type": "a list",
    "tuple_type": "a list",
    "finite_number": "a finite number",
}
_BOUNDS = {
    "greater_than": ">",
    "greater_than_equal": ">=",
    "less_than": "<",
    "less_than_equal": "<=",
}
_BOUND_KEYS = {
    "greater_than": "gt",
    "greater_than_equal": "ge",
    "less_than": "lt",
    "less_than_equal": "le",
}


M = TypeVar("M", bound=BaseModel)


def validate(raw: dict[str, Any], overrides: Mapping[str, object]) -> ScenarioModel:
    """The validated scenario model, or a `LocatedError` from the first validation error."""
    return validate_as(raw, overrides, ScenarioModel)


def validate_as(raw: dict[str, Any], overrides: Mapping[str, object], model: type[M]) -> M:
    """The validated `model` (the scenario file's, or another file's made of its parts,
    e.g. an OpenSCENARIO file's criteria), or a `LocatedError` from the first error."""
    try:
        return model.model_validate(raw)
    except ValidationError as exc:
        error = _first_error(exc.errors(include_url=False))
        key, message = _translate(error, raw, model)
        if any(key == path or key.startswith(path + ".") for path in overrides):
            message += " (set by an override)"
        raise LocatedError(key, message) from None


def _first_error(errors: list[ErrorDetails]) -> ErrorDetails:
    """The error to report: the first one, except that an unknown key beside a missing one
    (likely its misspelling) is reported instead of the missing key."""
    first = errors[0]
    if first["type"] == "missing":
        for error in errors:
            if error["type"] == "extra_forbidden" and error["loc"][:-1] == first["loc"][:-1]:
                return error
    return first


def _translate(error: ErrorDetails, raw: dict[str, Any],
               root: type[BaseModel]) -> tuple[str, str]:
    """A pydantic error as (dotted key path, friendly message)."""
    loc = _file_path(error["loc"], raw)
    context = error.get("ctx") or {}
    kind = error["type"]
    if kind == "avsim":
        if "key" in context:
            loc = (*loc, context["key"])
        return dotted(loc), str(context["problem"])
    if kind in {"union_tag_invalid", "union_tag_not_found"}:
        noun = str(loc[-2]).removesuffix("s") + " " if len(loc) >= 2 else ""
        tags = ", ".join(re.findall(r"'([^']*)'", str(context.get("expected_tags", ""))))
        if kind == "union_tag_not_found":
            return dotted((*loc, "type")), f"required key missing (the {noun}type)"
        got = context.get("tag")
        return dotted((*loc, "type")), f"unknown {noun}type {got!r} (expected one of {tags})"
    return dotted(loc), _message(error, loc, root)


def _message(error: ErrorDetails, loc: KeyPath, root: type[BaseModel]) -> str:
    """A pydantic error of a built-in type as a short message (`must be > 0, got -5`)."""
    kind = error["type"]
    context = error.get("ctx") or {}
    got = show(error.get("input"))
    if kind == "missing":
        too_few = bool(loc) and isinstance(loc[-1], int)
        return "item missing (too few items)" if too_few else "required key missing"
    if kind == "extra_forbidden":
        known = sorted(_keys_at(loc[:-1], root))
        close = difflib.get_close_matches(str(loc[-1]), known, n=1, cutoff=0.75)
        return f"unknown key (did you mean {close[0]}?)" if close else "unknown key"
    if kind in _EXPECTED:
        return f"must be {_EXPECTED[kind]}, got {got}"
    if kind in _BOUNDS:
        return f"must be {_BOUNDS[kind]} {fmt(context[_BOUND_KEYS[kind]])}, got {got}"
    if kind == "literal_error":
        choices = re.findall(r"'([^']*)'", str(context.get("expected", "")))
        expected = choices[0] if len(choices) == 1 else "one of " + ", ".join(choices)
        return f"must be {expected}, got {got}"
    if kind == "string_pattern_mismatch":
        pattern = str(context.get("pattern", "")).strip("^$")
        return f"must match {pattern} (lower-case letters, digits, _), got {got}"
    if kind in {"too_short", "too_long"}:
        bound = "at least" if kind == "too_short" else "at most"
        count = context.get("min_length" if kind == "too_short" else "max_length")
        return f"must have {bound} {count} item(s), got {context.get('actual_length')}"
    text = str(error["msg"])
    return text[:1].lower() + text[1:]


def _keys_at(parent: KeyPath, root: type[BaseModel]) -> set[str]:
    """The keys the format allows in the mapping at `parent` (for "did you mean" hints);
    for a feature, those of every feature type."""
    models: list[type[BaseModel]] = [root]
    for part in parent:
        if isinstance(part, int):  # a list item: `_models_in` already unwrapped the list
            continue
        fields = [m.model_fields[part] for m in models if part in m.model_fields]
        models = [m for field in fields for m in _models_in(field.annotation)]
    return {name for model in models for name in model.model_fields}


def _models_in(annotation: object) -> list[type[BaseModel]]:
    """The pydantic models inside a field's type (`X | None`, `list[X]`, unions)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [model for arg in get_args(annotation) for model in _models_in(arg)]


def _file_path(loc: Sequence[str | int], raw: object) -> KeyPath:
    """The error location as a path of the file's keys: pydantic adds union member names
    (a feature's `type`, ...) that are not keys of the file; they are dropped."""
    kept: list[str | int] = []
    node = raw
    for depth, part in enumerate(loc):
        child = _item(node, part)
        if child is not _ABSENT:
            node = child
        elif not (depth == len(loc) - 1 and isinstance(node, dict | list)):
            continue
        kept.append(part)
    return tuple(kept)


_ABSENT = object()  # `_item`'s answer for a key or index the file does not have


def _item(node: object, part: str | int) -> object:
    """`node[part]` for a mapping key or list index present in the file, else `_ABSENT`."""
    if isinstance(node, dict) and part in node:
        return node[part]
    if isinstance(node, list) and isinstance(part, int) and 0 <= part < len(node):
        return node[part]
    return _ABSENT


