"""`load_openscenario`: an OpenSCENARIO 1.0-1.3 file (.xosc) read, its parameters and
catalogs resolved, into the typed `OpenScenario` model; `declared_parameters` for sweeps.

Every problem is one `ScenarioError` line: `<file>: line N: <element path>: <problem>`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from types import MappingProxyType

from avsim.scenario.errors import FILE_KEY, ScenarioError
from avsim.scenario.openscenario.attributes import Attributes
from avsim.scenario.openscenario.catalogs import Catalogs
from avsim.scenario.openscenario.context import Context
from avsim.scenario.openscenario.model import OpenScenario
from avsim.scenario.openscenario.parameters import (
    ParameterInfo,
    evaluate_declarations,
    parse_declarations,
)
from avsim.scenario.openscenario.parse_entities import parse_entities
from avsim.scenario.openscenario.parse_global import parse_variable_declarations
from avsim.scenario.openscenario.parse_storyboard import parse_storyboard
from avsim.scenario.openscenario.references import ReferenceError, Roots, is_file
from avsim.scenario.openscenario.xmlread import Node, read_xml

SUPPORTED_MINOR = (0, 1, 2, 3)  # OpenSCENARIO 1.0 to 1.3
_NO_OVERRIDES: Mapping[str, str] = MappingProxyType({})


def _read_root(path: Path) -> tuple[Node, int, int]:
    root = read_xml(path)
    if root.tag != "OpenSCENARIO":
        raise root.error("not an OpenSCENARIO file (the root element is not OpenSCENARIO)")
    header = root.need("FileHeader")
    try:
        major = int(header.attrs.get("revMajor", ""))
        minor = int(header.attrs.get("revMinor", ""))
    except ValueError:
        raise header.error("revMajor and revMinor must be integers") from None
    if major != 1 or minor not in SUPPORTED_MINOR:
        raise header.error(f"not supported yet (OpenSCENARIO {major}.{minor})")
    catalog = root.child("Catalog")
    if catalog is not None:
        raise catalog.error("not supported yet (Catalog): this is not a scenario file")
    distribution = root.child("ParameterValueDistribution")
    if distribution is not None:  # `distribution.load_distribution` reads it
        raise distribution.error("a parameter distribution, not one scenario: `avsim run` "
                                 "runs each of its runs (--permutation K one), as `suite`")
    return root, major, minor


def scenario_roots(path: Path, search_paths: Sequence[Path]) -> Roots:
    """The folders the scenario file `path` may reference files in (`references`)."""
    try:
        return Roots.of(path, search_paths)
    except ReferenceError as exc:
        raise ScenarioError(str(path), "--search-path", str(exc)) from None


def declared_parameters(path: Path) -> tuple[ParameterInfo, ...]:
    """The scenario's global parameters as declared (type, default, constraint groups)."""
    root, _, _ = _read_root(path)
    return parse_declarations(root.child("ParameterDeclarations"))


def _road_network(root: Node, roots: Roots, attrs: Attributes) -> Path | None:
    network = root.need("RoadNetwork")
    signals = network.child("TrafficSignals")
    if signals is not None and signals.children:
        raise signals.children[0].error(f"not supported yet ({signals.children[0].tag})")
    logic = network.child("LogicFile")
    if logic is None:
        return None
    try:
        road = roots.find(attrs.text(logic, "filepath"))
    except ReferenceError as exc:
        raise logic.error(f"filepath: {exc}") from None
    if not is_file(road):
        raise logic.error(f"road network file not found: {road}")
    return road


def load_openscenario(path: Path, overrides: Mapping[str, str] = _NO_OVERRIDES,
                      search_paths: Sequence[Path] = ()) -> OpenScenario:
    """The scenario in the .xosc file at `path`, with the parameter values in `overrides`
    (name -> value as text) replacing the declared defaults; its road and catalogs found in
    its folder tree or in `search_paths` (`references`); `ScenarioError` on any problem."""
    path = Path(path)
    root, major, minor = _read_root(path)
    roots = scenario_roots(path, search_paths)
    scope = evaluate_declarations(
        root.child("ParameterDeclarations"), None, overrides, file=str(path)
    )
    attrs = Attributes(scope)
    catalogs = Catalogs.load(root.child("CatalogLocations"), roots, attrs)
    road_network = _road_network(root, roots, attrs)
    ctx = Context(attrs, catalogs, None)
    entities_node = root.child("Entities")
    entities = parse_entities(entities_node, ctx) if entities_node is not None else ()
    variables = parse_variable_declarations(root.child("VariableDeclarations"), ctx)
    ctx = Context(attrs, catalogs, frozenset(e.name for e in entities),
                  variables={v.name: v.variable_type for v in variables})
    storyboard_node = root.child("Storyboard")
    if storyboard_node is None:
        raise ScenarioError(str(path), FILE_KEY, "missing element Storyboard")
    header = root.need("FileHeader")
    return OpenScenario(
        path=path,
        rev_major=major,
        rev_minor=minor,
        description=header.attrs.get("description", ""),
        parameters=dict(scope.values),
        road_network=road_network,
        entities=entities,
        storyboard=parse_storyboard(storyboard_node, ctx),
        variables=variables,
    )


__all__ = ["declared_parameters", "load_openscenario", "scenario_roots"]
