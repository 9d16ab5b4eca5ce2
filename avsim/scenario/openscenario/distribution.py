"""`load_distribution`: an OpenSCENARIO 1.0-1.3 ParameterValueDistribution file read and
expanded into the concrete runs it describes: its scenario file (`ScenarioFile`, found as a
catalog is: in the distribution file's folder tree or a search path) and, per run, the
parameter values to set.

Deterministic distributions (`Deterministic`): each child is one axis of values, and the
runs are the Cartesian product of the axes in esmini's order: permutation k is the
mixed-radix number k with the last axis varying fastest (the first axis the most
significant digit), as `esmini --param_dist FILE --param_permutation k` plays it.

- `DeterministicSingleParameterDistribution parameterName=P`: one parameter.
  `DistributionSet`: its `Element value`s in order. `DistributionRange stepWidth=W` with
  `Range lowerLimit=L upperLimit=U`: L, L+W, L+2W, ... (added up step by step, in doubles)
  while the value is below U + 1e-6, so that U itself is included when the steps reach it,
  as esmini does; each value written with at most 6 decimals (esmini's text) and no
  trailing zeros (``30``, ``2.5``).
- `DeterministicMultiParameterDistribution / ValueSetDistribution`: each
  `ParameterValueSet` (its `ParameterAssignment parameterRef value`s) is one value of the
  axis.

A run's parameters are the chosen values of every axis in the file's order; a parameter
assigned twice takes the later value (esmini assigns them in that order).

Stochastic distributions (`Stochastic numberOfTestRuns randomSeed`):
`distribution_draws`. The number of runs a file describes is at most `MAX_RUNS`, checked
before a run is made.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from avsim.scenario.errors import ScenarioError
from avsim.scenario.openscenario.distribution_draws import stochastic_runs
from avsim.scenario.openscenario.distribution_values import (
    MAX_RUNS,
    Assignments,
    number,
    text,
)
from avsim.scenario.openscenario.parse import SUPPORTED_MINOR
from avsim.scenario.openscenario.references import ReferenceError, Roots, is_file
from avsim.scenario.openscenario.xmlread import Node, read_xml

PARAMETERS = "parameters."  # an OpenSCENARIO parameter's override key: `parameters.NAME`
RANGE_SLACK = 1e-6  # a range's upper limit is reached within this (esmini's SMALL_NUMBER)
ROOT = "ParameterValueDistribution"


@dataclass(frozen=True, slots=True)
class ConcreteRun:
    """One run a distribution describes: its permutation and its parameter values."""

    index: int  # 0-based (esmini's --param_permutation)
    parameters: Assignments  # (name, value as text) in the file's order, each name once

    def overrides(self) -> dict[str, object]:
        """The run's overrides for `load_scenario`: `parameters.NAME` -> value text."""
        return {PARAMETERS + name: value for name, value in self.parameters}

    def label(self) -> str:
        """``NAME=VALUE, ...`` for reports."""
        return ", ".join(f"{name}={value}" for name, value in self.parameters)


@dataclass(frozen=True, slots=True)
class Distribution:
    """A ParameterValueDistribution file, expanded."""

    path: Path  # the distribution file
    scenario: Path  # its ScenarioFile, resolved
    stochastic: bool  # drawn (`distribution_draws`) rather than enumerated
    runs: tuple[ConcreteRun, ...]  # in permutation order


def is_distribution(path: Path) -> bool:
    """Whether the `.xosc` file at `path` is a ParameterValueDistribution file (False for
    anything that cannot be read: loading it then says why)."""
    try:
        root = read_xml(Path(path))
    except ScenarioError:
        return False
    return root.tag == "OpenSCENARIO" and root.child(ROOT) is not None


def load_distribution(path: Path, search_paths: Sequence[Path] = ()) -> Distribution:
    """The runs of the distribution file at `path` (module doc); `ScenarioError` (one line)
    for a malformed or unsupported one, or one describing more than `MAX_RUNS` runs."""
    path = Path(path)
    root = read_xml(path)
    _check_header(root)
    node = root.need(ROOT)
    scenario = _scenario_file(node.need("ScenarioFile"), path, search_paths)
    deterministic, stochastic = node.child("Deterministic"), node.child("Stochastic")
    if (deterministic is None) == (stochastic is None):
        raise node.error("expected one of Deterministic or Stochastic")
    if deterministic is not None:
        runs = deterministic_runs(deterministic)
    else:
        assert stochastic is not None
        runs = stochastic_runs(stochastic)
    return Distribution(path, scenario, stochastic is not None,
                        tuple(ConcreteRun(k, _last_wins(p)) for k, p in enumerate(runs)))


def _check_header(root: Node) -> None:
    if root.tag != "OpenSCENARIO":
        raise root.error("not an OpenSCENARIO file (the root element is not OpenSCENARIO)")
    header = root.need("FileHeader")
    major, minor = header.attrs.get("revMajor", ""), header.attrs.get("revMinor", "")
    if major != "1" or not minor.isdigit() or int(minor) not in SUPPORTED_MINOR:
        raise header.error(f"not supported yet (OpenSCENARIO {text(major)}.{text(minor)})")


def _scenario_file(node: Node, path: Path, search_paths: Sequence[Path]) -> Path:
    written = node.attrs.get("filepath")
    if not written:
        raise node.error("missing attribute filepath")
    try:
        found = Roots.of(path, search_paths).find(written)
    except ReferenceError as exc:
        raise node.error(f"filepath: {exc}") from None
    if not is_file(found):
        raise node.error(f"scenario file not found: {found}")
    return found


def _last_wins(assignments: Assignments) -> Assignments:
    """Each name once, at its first place, with its last value."""
    values = dict(assignments)
    seen: dict[str, str] = {}
    for name, _ in assignments:
        seen.setdefault(name, values[name])
    return tuple(seen.items())


def deterministic_runs(node: Node) -> list[Assignments]:
    """Every permutation of a Deterministic element, in esmini's order (module doc)."""
    axes: list[list[Assignments]] = []
    for child in node.children:
        axis = _axis(child)
        if not axis:
            raise child.error("no values: the distribution would describe no run")
        axes.append(axis)
        if math.prod(len(a) for a in axes) > MAX_RUNS:
            raise node.error(f"more than {MAX_RUNS} permutations: at most {MAX_RUNS}")
    if not axes:
        raise node.error("no distribution: the distribution would describe no run")
    return [tuple(itertools.chain.from_iterable(choice)) for choice in itertools.product(*axes)]


def _axis(node: Node) -> list[Assignments]:
    """The values of one deterministic distribution, each a tuple of assignments."""
    if node.tag == "DeterministicMultiParameterDistribution":
        sets = node.need("ValueSetDistribution").all("ParameterValueSet")
        return [tuple((_attr(a, "parameterRef"), _attr(a, "value"))
                      for a in s.all("ParameterAssignment")) for s in sets]
    if node.tag != "DeterministicSingleParameterDistribution":
        raise node.error(f"not supported yet ({node.tag})")
    name = _attr(node, "parameterName")
    dist = node.only_child()
    values = SINGLE_DISTRIBUTIONS.get(dist.tag)
    if values is None:
        raise dist.error(f"not supported yet ({dist.tag})")
    return [((name, value),) for value in values(dist)]


SINGLE_DISTRIBUTIONS: dict[str, Callable[[Node], list[str]]] = {  # the values, as text
    "DistributionSet": lambda dist: [_attr(e, "value") for e in dist.all("Element")],
    "DistributionRange": lambda dist: list(range_values(dist)),
}


def _attr(node: Node, name: str) -> str:
    value = node.attrs.get(name)
    if value is None:
        raise node.error(f"missing attribute {name}")
    return value


def range_values(node: Node) -> list[str]:
    """A DistributionRange's values as text (module doc); refused when the step is not
    positive, the limits are reversed or the range holds more than `MAX_RUNS` steps."""
    step = number(node, "stepWidth")
    limits = node.need("Range")
    low, high = number(limits, "lowerLimit"), number(limits, "upperLimit")
    if step <= 0:
        raise node.error(f"stepWidth must be > 0, got {text(node.attrs['stepWidth'])}")
    if high < low:
        raise limits.error(f"upperLimit {high:g} is below lowerLimit {low:g}")
    if (high - low) / step > MAX_RUNS:
        raise node.error(f"more than {MAX_RUNS} steps: at most {MAX_RUNS}")
    values: list[str] = []
    value = low
    while value < high + RANGE_SLACK:
        values.append(_esmini_text(value))
        value += step
    return values


def _esmini_text(value: float) -> str:
    """`value` as esmini writes it (6 decimals), without trailing zeros."""
    written = f"{value:.6f}".rstrip("0").rstrip(".")
    return "0" if written in ("", "-0") else written


__all__ = ["ConcreteRun", "Distribution", "is_distribution", "load_distribution"]
