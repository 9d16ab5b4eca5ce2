"""What the readers of a ParameterValueDistribution file share: its bound on runs, a run's
parameter assignments, and attribute reading without a parameter scope (a distribution
file declares no parameters)."""

from __future__ import annotations

import math

from avsim.scenario.bounds import MAX_DISTRIBUTION_RUNS
from avsim.scenario.openscenario.xmlread import Node

MAX_RUNS = MAX_DISTRIBUTION_RUNS  # runs a distribution file may describe
SHOWN_CHARS = 40  # of an attribute's text in a message

Assignments = tuple[tuple[str, str], ...]  # (parameter name, value as text), in order


def text(value: str) -> str:
    """An attribute's text for a message: quoted, at most `SHOWN_CHARS` characters."""
    shown = value if len(value) <= SHOWN_CHARS else value[: SHOWN_CHARS - 3] + "..."
    return repr(shown)


def number(node: Node, name: str) -> float:
    """The finite number in attribute `name` of `node`; refused when missing or not one."""
    written = node.attrs.get(name)
    if written is None:
        raise node.error(f"missing attribute {name}")
    try:
        value = float(written)
    except ValueError:
        raise node.error(f"{name}: expected a number, got {text(written)}") from None
    if not math.isfinite(value):
        raise node.error(f"{name}: expected a finite number, got {text(written)}")
    return value + 0.0  # -0.0 as 0.0: numpy refuses a sigma or a range of -0.0


def optional_number(node: Node, name: str, default: float) -> float:
    """`number`, or `default` when the attribute is absent."""
    return number(node, name) if name in node.attrs else default
