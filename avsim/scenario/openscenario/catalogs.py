"""Catalogs: CatalogLocations (directories relative to the scenario file's folder, or a
search path: `references`), the catalog files in them (bounded in number and bytes), and
CatalogReference resolution with ParameterAssignments.

Every `.xosc` file in a location's directory is read; each holds one `<Catalog name=...>`
whose children are its entries. A reference names a catalog and an entry; the entry's own
ParameterDeclarations get the reference's assignments (resolved in the referencing scope)
and are evaluated in a scope of their own (catalog entries do not see the scenario's
global parameters).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from avsim.scenario.errors import ScenarioError
from avsim.scenario.openscenario.attributes import Attributes
from avsim.scenario.openscenario.parameters import (
    Scope,
    evaluate_declarations,
    parse_declarations,
)
from avsim.scenario.openscenario.references import ReferenceError, Roots, is_dir
from avsim.scenario.openscenario.xmlread import MAX_FILE_BYTES, Node, read_xml_sized

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
MAX_CATALOG_FILES = 100  # the most catalog files a scenario's CatalogLocations may hold
MAX_CATALOG_BYTES = MAX_FILE_BYTES  # [bytes] their sizes added up


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
    def load(cls, locations: Node | None, roots: Roots, attrs: Attributes) -> Catalogs:
        """Reads every catalog file under the CatalogLocations element `locations`, each
        directory found in the scenario's folder tree or a search path (`roots`)."""
        entries: dict[str, dict[str, Node]] = {}
        if locations is None:
            return cls(entries)
        files: list[Path] = []
        read: set[Path] = set()  # a directory may serve several kinds; read it once
        for loc in locations.children:
            if loc.tag not in CATALOG_LOCATIONS:
                raise loc.error(f"not supported yet ({loc.tag})")
            directory_node = loc.need("Directory")
            directory = _directory(directory_node, roots, attrs)
            if directory in read:
                continue
            read.add(directory)
            files += _catalog_files(directory, directory_node, len(files))
        budget = MAX_CATALOG_BYTES
        for file in files:
            budget -= _read_catalog_file(file, roots, entries, budget)
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
            declarations, None, assignments, file=entry.file, overrides_from="assignment",
            budget=attrs.scope.budget,
        )
        return CatalogEntry(catalog, name, entry, scope)


def _directory(node: Node, roots: Roots, attrs: Attributes) -> Path:
    """The catalog directory a Directory element names, resolved and checked."""
    try:
        directory = roots.find(attrs.text(node, "path"))
    except ReferenceError as exc:
        raise node.error(f"path: {exc}") from None
    if not is_dir(directory):
        raise node.error(f"catalog directory not found: {directory}")
    return directory


def _catalog_files(directory: Path, node: Node, before: int) -> list[Path]:
    """The `.xosc` files of a catalog directory, sorted; at most MAX_CATALOG_FILES in all
    (`before` already listed)."""
    files: list[Path] = []
    try:
        for file in directory.iterdir():
            if file.suffix != ".xosc":
                continue
            files.append(file)
            if before + len(files) > MAX_CATALOG_FILES:
                raise node.error(f"over {MAX_CATALOG_FILES} catalog files: at most "
                                 f"{MAX_CATALOG_FILES}")
    except OSError as exc:
        raise node.error(f"cannot list the catalog directory ({exc.strerror})") from None
    return sorted(files)


def _read_catalog_file(file: Path, roots: Roots, entries: dict[str, dict[str, Node]],
                       budget: int) -> int:
    """Reads one catalog file (at most `budget` bytes) into `entries`; its size [bytes]."""
    try:
        roots.check(file)
    except ReferenceError as exc:
        raise ScenarioError(str(file), "(file)", str(exc)) from None
    if budget <= 0:
        raise ScenarioError(str(file), "(file)", f"the catalogs hold over {MAX_CATALOG_BYTES} "
                            f"bytes: at most {MAX_CATALOG_BYTES}")
    root, size = read_xml_sized(file, min(budget, MAX_FILE_BYTES))
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
    return size
