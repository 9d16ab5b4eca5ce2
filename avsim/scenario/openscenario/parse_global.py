"""Reading VariableDeclarations and GlobalAction elements: EnvironmentAction
(`parse_environment`), EntityAction (`parse_entity_actions`), VariableAction and the
deprecated ParameterAction (SetAction, ModifyAction with AddValue or MultiplyByValue).
Other GlobalActions are refused.

A variable or parameter an action or a condition names must be declared (variables in the
file's VariableDeclarations, parameters in scope); a value set is converted to its type
and a modification needs a numeric one, all when the file is read."""

from __future__ import annotations

from collections.abc import Callable, Mapping

from avsim.scenario.openscenario.attributes import unsupported
from avsim.scenario.openscenario.context import Context
from avsim.scenario.openscenario.global_actions import GlobalAction
from avsim.scenario.openscenario.parameters import (
    PARAMETER_TYPES,
    ParameterType,
    ParamValue,
    ResolveError,
    convert,
    resolve,
)
from avsim.scenario.openscenario.parse_entity_actions import parse_entity_action
from avsim.scenario.openscenario.parse_environment import parse_environment_action
from avsim.scenario.openscenario.variables import (
    NUMERIC_TYPES,
    ModifyValue,
    SetValue,
    VariableAction,
    VariableDeclaration,
)
from avsim.scenario.openscenario.xmlread import Node

VARIABLE_TYPES = tuple(t for t in PARAMETER_TYPES if t != "integer")  # 1.2's names


def parse_variable_declarations(node: Node | None,
                                ctx: Context) -> tuple[VariableDeclaration, ...]:
    """The VariableDeclaration children of a VariableDeclarations element; each value may
    reference the scenario's parameters."""
    if node is None:
        return ()
    found: dict[str, VariableDeclaration] = {}
    for decl in node.all("VariableDeclaration"):
        name = ctx.attrs.text(decl, "name")
        if name in found:
            raise decl.error(f"variable {name} declared twice")
        vtype = ctx.attrs.choice(decl, "variableType", VARIABLE_TYPES)
        raw = ctx.attrs.value(decl, "value")
        if raw is None:
            raise decl.error("missing attribute value")
        found[name] = VariableDeclaration(name, vtype,  # type: ignore[arg-type]
                                          _typed(decl, "value", raw, vtype))  # type: ignore[arg-type]
    return tuple(found.values())


def type_of(value: ParamValue) -> ParameterType:
    """The parameter type a resolved parameter value has (a dateTime's is its text)."""
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, int):
        return "int"
    return "double" if isinstance(value, float) else "string"


def _typed(node: Node, attr: str, value: ParamValue, vtype: ParameterType) -> ParamValue:
    try:
        return convert(value, vtype)
    except ResolveError as exc:
        raise node.error(f"{attr}: {exc}") from None


def _target_type(node: Node, ctx: Context, target: str) -> tuple[str, ParameterType]:
    if target == "variable":
        name = ctx.attrs.text(node, "variableRef")
        declared: Mapping[str, ParameterType] = ctx.variables or {}
        if name not in declared:
            known = ", ".join(sorted(declared)) or "none"
            raise node.error(f"variableRef: no variable {name} (variables: {known})")
        return name, declared[name]
    name = ctx.attrs.text(node, "parameterRef")
    current = ctx.attrs.scope.get(name)
    if current is None:
        raise node.error(f"parameterRef: no parameter {name}")
    return name, type_of(current)


def _change(node: Node, ctx: Context, name: str, vtype: ParameterType) -> SetValue | ModifyValue:
    body = node.only_child()
    if body.tag == "SetAction":
        raw = body.attrs.get("value")
        if raw is None:
            raise body.error("missing attribute value")
        try:
            value = resolve(raw, ctx.attrs.scope)
        except ResolveError as exc:
            raise body.error(f"value: {exc}") from None
        return SetValue(_typed(body, "value", value, vtype))
    if body.tag != "ModifyAction":
        raise unsupported(body)
    if vtype not in NUMERIC_TYPES:
        raise body.error(f"{name} is a {vtype}: only a number can be modified")
    rule = body.need("Rule").only_child()
    if rule.tag not in ("AddValue", "MultiplyByValue"):
        raise unsupported(rule)
    return ModifyValue("add" if rule.tag == "AddValue" else "multiply",
                       ctx.attrs.number(rule, "value"))


def _variable_action(node: Node, ctx: Context, target: str) -> VariableAction:
    name, vtype = _target_type(node, ctx, target)
    return VariableAction(target, name, vtype, _change(node, ctx, name, vtype))  # type: ignore[arg-type]


GLOBAL_READERS: dict[str, Callable[[Node, Context], GlobalAction]] = {
    "EnvironmentAction": parse_environment_action,
    "EntityAction": parse_entity_action,
    "VariableAction": lambda n, c: _variable_action(n, c, "variable"),
    "ParameterAction": lambda n, c: _variable_action(n, c, "parameter"),
}


def parse_global_action(node: Node, ctx: Context) -> GlobalAction:
    """The action a GlobalAction element holds (`GLOBAL_READERS`)."""
    body = node.only_child()
    reader = GLOBAL_READERS.get(body.tag)
    if reader is None:
        raise unsupported(body)
    return reader(body, ctx)
