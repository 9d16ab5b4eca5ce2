"""Typed attribute reading: each attribute resolved (`$name`, `${...}`) in a parameter scope
and converted, with any problem reported at the element (`line N: <path>: <attr>: ...`)."""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass

from avsim.scenario.errors import ScenarioError, fmt
from avsim.scenario.openscenario.limits import MAX_NAME_CHARS
from avsim.scenario.openscenario.parameters import (
    ParamValue,
    ResolveError,
    Scope,
    brief,
    resolve,
    to_bool,
    to_float,
    to_int,
    to_str,
)
from avsim.scenario.openscenario.xmlread import Node


def unsupported(node: Node) -> ScenarioError:
    """The error for an element this reader does not handle yet."""
    return node.error(f"not supported yet ({node.tag})")


def _within(node: Node, name: str, value: float, low: float, high: float, unit: str) -> float:
    if not low <= value <= high:
        raise node.error(f"{name}: must be in [{fmt(low)}, {fmt(high)}] {unit}, got {fmt(value)}")
    return value


@dataclass(frozen=True, slots=True)
class Attributes:
    """Reads the attributes of elements in one parameter scope."""

    scope: Scope

    def value(self, node: Node, name: str) -> ParamValue | None:
        raw = node.attrs.get(name)
        if raw is None:
            return None
        try:
            return resolve(raw, self.scope)
        except ResolveError as exc:
            raise node.error(f"{name}: {exc}") from None

    def _need(self, node: Node, name: str) -> ParamValue:
        value = self.value(node, name)
        if value is None:
            raise node.error(f"missing attribute {name}")
        return value

    def text(self, node: Node, name: str) -> str:
        """An attribute as text; a `name` (of an entity, a storyboard element, a catalog
        entry, ...) at most MAX_NAME_CHARS long."""
        value = to_str(self._need(node, name))
        if name == "name" and len(value) > MAX_NAME_CHARS:
            raise node.error(f"name: {len(value)} characters: at most {MAX_NAME_CHARS}")
        return value

    def opt_text(self, node: Node, name: str) -> str | None:
        value = self.value(node, name)
        return None if value is None else to_str(value)

    def number(self, node: Node, name: str) -> float:
        try:
            return to_float(self._need(node, name))
        except ResolveError as exc:
            raise node.error(f"{name}: {exc}") from None

    def opt_number(self, node: Node, name: str, default: float | None = None) -> float | None:
        value = self.value(node, name)
        if value is None:
            return default
        try:
            return to_float(value)
        except ResolveError as exc:
            raise node.error(f"{name}: {exc}") from None

    def bounded(self, node: Node, name: str, low: float, high: float, unit: str) -> float:
        """A number in [low, high] (`unit` for the message); an error outside."""
        return _within(node, name, self.number(node, name), low, high, unit)

    def opt_bounded(self, node: Node, name: str, low: float, high: float,
                    unit: str) -> float | None:
        """An optional number in [low, high]; None when the attribute is absent."""
        value = self.opt_number(node, name)
        return None if value is None else _within(node, name, value, low, high, unit)

    def number_or(self, node: Node, name: str, default: float) -> float:
        value = self.opt_number(node, name, default)
        assert value is not None
        return value

    def integer(self, node: Node, name: str) -> int:
        try:
            return to_int(self._need(node, name))
        except ResolveError as exc:
            raise node.error(f"{name}: {exc}") from None

    def integer_or(self, node: Node, name: str, default: int) -> int:
        if name not in node.attrs:
            return default
        return self.integer(node, name)

    def boolean(self, node: Node, name: str) -> bool:
        try:
            return to_bool(self._need(node, name))
        except ResolveError as exc:
            raise node.error(f"{name}: {exc}") from None

    def opt_boolean(self, node: Node, name: str) -> bool | None:
        if name not in node.attrs:
            return None
        return self.boolean(node, name)

    def boolean_or(self, node: Node, name: str, default: bool) -> bool:
        found = self.opt_boolean(node, name)
        return default if found is None else found

    def choice(self, node: Node, name: str, allowed: Collection[str]) -> str:
        text = self.text(node, name)
        if text not in allowed:
            raise node.error(f"{name}: {brief(text)} is not one of {', '.join(allowed)}")
        return text

    def choice_or(self, node: Node, name: str, allowed: Collection[str], default: str) -> str:
        if name not in node.attrs:
            return default
        return self.choice(node, name, allowed)

    def properties(self, node: Node | None) -> dict[str, str]:
        """A Properties element's Property name -> value (File children ignored)."""
        if node is None:
            return {}
        return {self.text(p, "name"): self.text(p, "value") for p in node.all("Property")}
