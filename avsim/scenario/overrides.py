"""Overrides: values set into a scenario file's data before it is validated.

`avsim sweep --set PATH=V` and `avsim run --seed` give them as dotted key paths with list
indices (`actors.0.speed_kph`). Every mapping and list on the way must exist and list
indices be in range; the last key may be new (validation then rejects it if the format has
no such key). A bad path is a `LocatedError` at that path. The one exception: under a
top-level section in ``NEW_SECTIONS`` (whole optional sections of the format), mappings the
file leaves out are made, empty, on the way (`--stack` sets `stack.stack` in a file with no
`stack:`; `--set sensors.gnss.preset=rtk` in one with no `sensors:`); validation then
judges every key so made.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from typing import Any

from avsim.scenario.errors import LocatedError, show

NEW_SECTIONS = frozenset({"stack", "sensors", "criteria"})  # top-level sections under which
#   an override may make the mappings on its way


def apply_overrides(raw: dict[str, Any], overrides: Mapping[str, object]) -> dict[str, Any]:
    """A copy of `raw` with each dotted `path` set to its value (before validation).

    Every mapping and list on the way must exist and list indices be in range; the last key
    may be new (validation then rejects it if the format has no such key)."""
    data = copy.deepcopy(raw)
    for path, value in overrides.items():
        _set_path(data, path, copy.deepcopy(value))
    return data


def _set_path(data: dict[str, Any], path: str, value: object) -> None:
    """Set the dotted `path` of `data` to `value` in place (module doc)."""
    parts = path.split(".")
    if not all(parts):
        raise LocatedError(path or "(override)", "override path is empty or has an empty part")
    node: object = data
    making = parts[0] in NEW_SECTIONS  # mappings on the way may be made
    for depth, part in enumerate(parts[:-1]):
        if making and isinstance(node, dict) and node.get(part) is None \
                and not part.isdigit():
            node[part] = {}
        node = _child(node, part, ".".join(parts[: depth + 1]), path)
    last = parts[-1]
    if isinstance(node, list):
        node[_index(node, last, path)] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise LocatedError(
            path, f"cannot set: {'.'.join(parts[:-1])} is {show(node)}, not a mapping or list"
        )


def _child(node: object, part: str, where: str, path: str) -> object:
    """The item `part` of the mapping or list `node` on the way along an override path."""
    if isinstance(node, list):
        return node[_index(node, part, path)]
    if isinstance(node, dict):
        if part not in node:
            raise LocatedError(path, f"cannot set: the file has no key {where}")
        return node[part]
    raise LocatedError(
        path, f"cannot set: {where.rpartition('.')[0]} is {show(node)}, not a mapping or list"
    )


def _index(node: list[Any], part: str, path: str) -> int:
    """`part` as an index of the list `node`, or a `LocatedError` at `path`."""
    if not part.isdigit() or int(part) >= len(node):
        raise LocatedError(path, f"cannot set: {part!r} is not an index of a list of {len(node)}")
    return int(part)

