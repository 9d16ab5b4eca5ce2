"""`avsim sweep`: the Cartesian grid of key overrides (`--set PATH=V1,V2,...`).

Each `--set` names one dotted key path of the scenario file (list indices as numbers:
``actors.0.speed_kph``) and its values, separated by commas outside brackets, so that a
value may itself be a list (``actors.0.start=[2,1,west],[3,1,west]``). Every value is
read as YAML (``20`` an int, ``2.5`` a float, ``west`` a string, ``[2, 1, west]`` a list),
exactly as it would be written in the file (`avsim.scenario.files.parse_value`: YAML 1.2).
The grid is the product of the `--set`s in the order given, the last varying fastest; run k
is named ``<scenario>_<k:03d>``. It holds at most `MAX_GRID_POINTS` points, as a file's own
`grid:` does: the product of the value counts is checked before a value is read or a point
made.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import yaml

from avsim.scenario.files import parse_value
from avsim.scenario.model import MAX_GRID_POINTS
from avsim.scenario.yaml_events import YamlBoundError

PATH_CHARS = set("abcdefghijklmnopqrstuvwxyz0123456789_.")  # of a dotted key path
PARAMETERS = "parameters."  # an OpenSCENARIO file's parameter: `parameters.NAME`
PARAMETER_CHARS = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_")
OPENING, CLOSING = "[{", "]}"  # YAML flow brackets: no value splits inside them
SHOWN_CHARS = 60  # of a `--set` text in a message: it may be a value of any length


class SweepError(ValueError):
    """A `--set` that cannot be read: the message names it."""


@dataclass(frozen=True, slots=True)
class Axis:
    """One swept key and its values."""

    path: str  # dotted key path into the scenario file
    values: tuple[object, ...]  # as YAML reads them

    def labels(self) -> list[str]:
        """Each value as written after `--set PATH=`."""
        return [format_value(v) for v in self.values]


def parse_set(text: str) -> Axis:
    """One `--set PATH=V1,V2,...` (module doc)."""
    path, sep, values = text.partition("=")
    path = path.strip()
    shown = _clipped(text)
    if not sep or not path:
        raise SweepError(f"--set {shown}: expected PATH=V1,V2,...")
    if not _is_key_path(path):
        raise SweepError(f"--set {shown}: {_clipped(path)!r} is not a dotted key path (a.b.0.c)")
    items = split_values(values)
    if len(items) > MAX_GRID_POINTS:
        raise SweepError(f"--set {shown}: {len(items)} values: at most {MAX_GRID_POINTS}")
    if not items or any(not item.strip() for item in items):
        raise SweepError(f"--set {shown}: an empty value")
    parsed = []
    for item in items:
        try:
            parsed.append(parse_value(item))
        except YamlBoundError as exc:
            raise SweepError(f"--set {shown}: {exc.problem}") from None
        except yaml.YAMLError:
            raise SweepError(f"--set {shown}: {_clipped(item)!r} is not a YAML value") from None
    if len({format_value(v) for v in parsed}) != len(parsed):
        raise SweepError(f"--set {shown}: a value is given twice")
    return Axis(path, tuple(parsed))


def _clipped(text: str) -> str:
    """`text` for a message: its first `SHOWN_CHARS` characters, `...` if there are more."""
    return text if len(text) <= SHOWN_CHARS else text[: SHOWN_CHARS - 3] + "..."


def _is_key_path(path: str) -> bool:
    """A dotted key path, or `parameters.NAME` (an OpenSCENARIO parameter's name: letters
    of either case, digits, _)."""
    name = path.removeprefix(PARAMETERS)
    if name != path:
        return bool(name) and set(name) <= PARAMETER_CHARS
    return (set(path) <= PATH_CHARS and not path.startswith(".") and not path.endswith(".")
            and ".." not in path)


def split_values(text: str) -> list[str]:
    """Split at the commas outside brackets."""
    items, depth, start = [], 0, 0
    for k, ch in enumerate(text):
        if ch in OPENING:
            depth += 1
        elif ch in CLOSING:
            depth -= 1
        elif ch == "," and depth == 0:
            items.append(text[start:k])
            start = k + 1
    items.append(text[start:])
    return items


def grid(axes: Sequence[Axis]) -> list[dict[str, object]]:
    """The overrides of each run: the product of the axes, the last varying fastest; a
    `SweepError` over `MAX_GRID_POINTS` points, before any is made."""
    paths = [a.path for a in axes]
    if len(set(paths)) != len(paths):
        raise SweepError("--set: a key path is swept twice")
    points = math.prod(len(a.values) for a in axes)
    if points > MAX_GRID_POINTS:
        raise SweepError(f"--set: a grid of {points} points: at most {MAX_GRID_POINTS}")
    return [dict(zip(paths, values, strict=True))
            for values in itertools.product(*(a.values for a in axes))]


def format_value(value: object) -> str:
    """A value as one would write it after `--set PATH=` (flow-style YAML)."""
    if isinstance(value, str):
        return value
    text: str = yaml.safe_dump(value, default_flow_style=True, width=1_000_000)
    return text.strip().removesuffix("...").strip()
