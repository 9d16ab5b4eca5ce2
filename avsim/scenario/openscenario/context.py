"""What the element readers share: the attribute reader of the current parameter scope, the
catalogs, and the declared entity names (to check entity references)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace

from avsim.scenario.openscenario.attributes import Attributes
from avsim.scenario.openscenario.catalogs import Catalogs
from avsim.scenario.openscenario.parameters import ParameterType, Scope, evaluate_declarations
from avsim.scenario.openscenario.xmlread import Node


@dataclass(frozen=True, slots=True)
class Context:
    attrs: Attributes
    catalogs: Catalogs
    entity_names: frozenset[str] | None  # None while the entities are being read
    element_names: Mapping[str, frozenset[str]] | None = None  # storyboard names by type
    declared_for: Node | None = None  # the element whose declarations `attrs` already has
    variables: Mapping[str, ParameterType] | None = None  # declared variables' types (1.2+)

    def in_scope(self, scope: Scope, entry: Node | None = None) -> Context:
        """This context reading attributes in another scope: a catalog entry's (`entry`,
        whose ParameterDeclarations the scope already holds, assignments applied)."""
        return replace(self, attrs=Attributes(scope), declared_for=entry)

    def with_declarations(self, node: Node) -> Context:
        """This context with the ParameterDeclarations under `node` (if any) in scope."""
        declarations = node.child("ParameterDeclarations")
        if declarations is None or node is self.declared_for:
            return self
        scope = evaluate_declarations(declarations, self.attrs.scope, {}, file=node.file)
        return self.in_scope(scope, node)

    def entity_ref(self, node: Node, name: str = "entityRef") -> str:
        """An entity reference attribute, checked against the declared entities."""
        entity = self.attrs.text(node, name)
        if self.entity_names is not None and entity not in self.entity_names:
            known = ", ".join(sorted(self.entity_names))
            raise node.error(f"{name}: no entity {entity} (entities: {known})")
        return entity

    def element_ref(self, node: Node, element_type: str, name: str) -> str:
        """A storyboard element reference (`CutInAction`, or 1.2's qualified
        `CutInStory::CutInAct`), checked against the storyboard's elements of that type."""
        ref = self.attrs.text(node, name)
        if self.element_names is None:
            return ref
        known = self.element_names.get(element_type, frozenset())
        if ref.split("::")[-1] not in known:
            listing = ", ".join(sorted(known)) or "none"
            raise node.error(f"{name}: no {element_type} {ref} (the {element_type}s: {listing})")
        return ref
