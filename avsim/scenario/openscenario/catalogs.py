"""Catalogs: CatalogLocations (directories relative to the scenario file's folder), the
catalog files in them, and CatalogReference resolution with ParameterAssignments.

Every `.xosc` file in a location's directory is read; each holds one `<Catalog name=...>`
whose children are its entries. A reference names a catalog and an entry; the entry's own
ParameterDeclarations get the reference's assignments (resolved in the referencing scope)
and are evaluated in a scope of their own (catalog entries do not see the scenario's
global parameters).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from avsim.scenario.openscenario.attributes import Attributes
from avsim.scenario.openscenario.parameters import (
    Scope,
    evaluate_declarations,
    parse_declarations,
)
from avsim.scenario.openscenario.xmlread import Node, read_xml

CATALOG_LOCATIONS: tuple[str, ...] = (
    "VehicleCatalog",
    "ControllerCatalog",
    "PedestrianCatalog",
    "MiscObjectCatalog",
    "EnvironmentCatalog",
    "ManeuverCatalog",
    "TrajectoryCatalog",
    "RouteCatalog",
    "SensorCatalog",
)  # all accepted and read; entries are used by kind (Vehicle, Controller, ...)


@dataclass(frozen=True, slots=True)
class CatalogEntry:
    """An entry resolved for one reference: its element and its parameters' scope."""

    catalog: str
    name: str
    node: Node  # the entry element (Vehicle, Controller, Maneuver, ...)
    scope: Scope  # its parameters with the reference's assignments


class Catalogs:
    """The catalogs a scenario's CatalogLocations name, by catalog name then entry name."""

    def __init__(self, entries: dict[str, dict[str, Node]]) -> None:
        self.entries = entries

    @classmethod
    def load(cls, locations: Node | None, base_dir: Path, attrs: Attributes) -> Catalogs:
        """Reads every catalog file under the CatalogLocations element `locations`."""
        entries: dict[str, dict[str, Node]] = {}
        if locations is None:
            return cls(entries)
        read: set[Path] = set()  # a directory may serve several kinds; read it once
        for loc in locations.children:
            if loc.tag not in CATALOG_LOCATIONS:
                raise loc.error(f"not supported yet ({loc.tag})")
            directory_node = loc.need("Directory")
            directory = (base_dir / attrs.text(directory_node, "path")).resolve()
            if not directory.is_dir():
                raise directory_node.error(f"catalog directory not found: {directory}")
            if directory in read:
                continue
            read.add(directory)
            for file in sorted(directory.glob("*.xosc")):
                _read_catalog_file(file, entries)
        return cls(entries)

    def resolve(self, ref: Node, attrs: Attributes, kinds: tuple[str, ...]) -> CatalogEntry:
        """The entry a CatalogReference element names, which must be one of `kinds`
        (element tags), with its parameters evaluated."""
        catalog = attrs.text(ref, "catalogName")
        name = attrs.text(ref, "entryName")
        if catalog not in self.entries:
            known = ", ".join(sorted(self.entries)) or "none"
            raise ref.error(f"no catalog named {catalog} (loaded: {known})")
        entry = self.entries[catalog].get(name)
        if entry is None:
            known = ", ".join(sorted(self.entries[catalog]))
            raise ref.error(f"no entry {name} in catalog {catalog} (entries: {known})")
        if entry.tag not in kinds:
            raise ref.error(
                f"entry {name} of catalog {catalog} is a {entry.tag}, not a " + " or ".join(kinds)
            )
        declarations = entry.child("ParameterDeclarations")
        declared = {info.name for info in parse_declarations(declarations)}
        assignments: dict[str, str] = {}
        holder = ref.child("ParameterAssignments")
        for assignment in holder.all("ParameterAssignment") if holder is not None else []:
            param = attrs.text(assignment, "parameterRef")
            if param not in declared:
                known = ", ".join(sorted(declared)) or "none"
                raise assignment.error(
                    f"entry {name} of catalog {catalog} declares no parameter {param} "
                    f"(declared: {known})"
                )
            assignments[param] = attrs.text(assignment, "value")
        scope = evaluate_declarations(
            declarations, None, assignments, file=entry.file, overrides_from="assignment"
        )
        return CatalogEntry(catalog, name, entry, scope)


def _read_catalog_file(file: Path, entries: dict[str, dict[str, Node]]) -> None:
    root = read_xml(file)
    catalog = root.need("Catalog")
    catalog_name = catalog.attrs.get("name")
    if catalog_name is None:
        raise catalog.error("missing attribute name")
    table = entries.setdefault(catalog_name, {})
    for entry in catalog.children:
        entry_name = entry.attrs.get("name")
        if entry_name is None:
            raise entry.error("missing attribute name")
        if entry_name in table:
            raise entry.error(f"entry {entry_name} is already in catalog {catalog_name}")
        table[entry_name] = entry
