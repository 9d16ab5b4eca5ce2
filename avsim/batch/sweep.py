"""`avsim sweep`: the Cartesian grid of key overrides (`--set PATH=V1,V2,...`).

Each `--set` names one dotted key path of the scenario file (list indices as numbers:
``actors.0.speed_kph``) and its values, separated by commas outside brackets, so that a
value may itself be a list (``actors.0.start=[2,1,west],[3,1,west]``). Every value is
read as YAML (``20`` an int, ``2.5`` a float, ``west`` a string, ``[2, 1, west]`` a list),
exactly as it would be written in the file (`avsim.scenario.files.parse_value`: YAML 1.2).
The grid is the product of the `--set`s in the order given, the last varying fastest; run k
is named ``<scenario>_<k:03d>``.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import yaml

from avsim.scenario.files import parse_value

PATH_CHARS = set("abcdefghijklmnopqrstuvwxyz0123456789_.")  # of a dotted key path
PARAMETERS = "parameters."  # an OpenSCENARIO file's parameter: `parameters.NAME`
PARAMETER_CHARS = set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_")
OPENING, CLOSING = "[{", "]}"  # YAML flow brackets: no value splits inside them


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
    if not sep or not path:
        raise SweepError(f"--set {text}: expected PATH=V1,V2,...")
    if not _is_key_path(path):
        raise SweepError(f"--set {text}: {path!r} is not a dotted key path (a.b.0.c)")
    items = split_values(values)
    if not items or any(not item.strip() for item in items):
        raise SweepError(f"--set {text}: an empty value")
    parsed = []
    for item in items:
        try:
            parsed.append(parse_value(item))
        except yaml.YAMLError:
            raise SweepError(f"--set {text}: {item!r} is not a YAML value") from None
    if len({format_value(v) for v in parsed}) != len(parsed):
        raise SweepError(f"--set {text}: a value is given twice")
    return Axis(path, tuple(parsed))


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
    """The overrides of each run: the product of the axes, the last varying fastest."""
    paths = [a.path for a in axes]
    if len(set(paths)) != len(paths):
        raise SweepError("--set: a key path is swept twice")
    return [dict(zip(paths, values, strict=True))
            for values in itertools.product(*(a.values for a in axes))]


def format_value(value: object) -> str:
    """A value as one would write it after `--set PATH=` (flow-style YAML)."""
    if isinstance(value, str):
        return value
    text: str = yaml.safe_dump(value, default_flow_style=True, width=1_000_000)
    return text.strip().removesuffix("...").strip()
