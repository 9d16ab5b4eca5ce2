"""Variables (OpenSCENARIO 1.2+: VariableDeclarations, VariableAction) and the deprecated
ParameterAction: typed values of the storyboard's run-time state. A variable or parameter
keeps its declared type; a value set is converted to it when the file is read."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from avsim.scenario.openscenario.parameters import ParameterType, ParamValue

NUMERIC_TYPES: tuple[str, ...] = ("int", "integer", "unsignedInt", "unsignedShort", "double")


@dataclass(frozen=True, slots=True)
class VariableDeclaration:
    name: str
    variable_type: ParameterType
    value: ParamValue  # the initial value, of `variable_type`


@dataclass(frozen=True, slots=True)
class SetValue:
    """SetAction: the value, already of the variable's (parameter's) type."""

    value: ParamValue


@dataclass(frozen=True, slots=True)
class ModifyValue:
    """ModifyAction: AddValue (`add`) or MultiplyByValue (`multiply`) on a numeric value."""

    rule: Literal["add", "multiply"]
    value: float  # [-] the operand, in the variable's unit for `add`


@dataclass(frozen=True, slots=True)
class VariableAction:
    """Sets or modifies a variable (`target` "variable") or, with the deprecated
    ParameterAction, a global parameter (`target` "parameter")."""

    target: Literal["variable", "parameter"]
    name: str
    value_type: ParameterType  # the declared type of the variable or parameter
    change: SetValue | ModifyValue


def apply_change(now: ParamValue, action: VariableAction) -> ParamValue:
    """The value after `action` on a value `now` (of the action's declared type). An
    integer adds the operand truncated to an integer, and a product is truncated, as
    esmini does; a double adds and multiplies exactly."""
    change = action.change
    if isinstance(change, SetValue):
        return change.value
    if isinstance(now, bool | str):
        raise TypeError(f"{action.name}: {type(now).__name__} cannot be modified")
    if isinstance(now, int):
        return now + int(change.value) if change.rule == "add" else int(now * change.value)
    return now + change.value if change.rule == "add" else now * change.value
