"""ParameterDeclarations: typed parameters, `$name` references and `${...}` expressions in
attributes, ConstraintGroups, and overrides.

A parameter's value may reference parameters declared before it. A value is valid when it
satisfies every ValueConstraint of at least one of its ConstraintGroups (the groups are
ORed, the constraints within one group ANDed; OpenSCENARIO 1.2, ValueConstraintGroup); a
parameter without groups is unconstrained. Constraint values may be expressions over the
other parameters of the same declarations, so the checks run once all are evaluated.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from datetime import datetime
from typing import Literal

from avsim.scenario.errors import ScenarioError, fmt
from avsim.scenario.openscenario.expressions import ExpressionError, Value, evaluate
from avsim.scenario.openscenario.limits import MAX_NAME_CHARS
from avsim.scenario.openscenario.xmlread import Node

ParamValue = int | float | bool | str  # a parameter's value (dateTime kept as its text)
ParameterType = Literal[
    "int", "integer", "unsignedInt", "unsignedShort", "double", "string", "boolean", "dateTime"
]  # "int" is 1.2's name for 1.0/1.1's "integer"
Rule = Literal["equalTo", "greaterThan", "lessThan", "greaterOrEqual", "lessOrEqual", "notEqualTo"]

PARAMETER_TYPES: tuple[str, ...] = (
    "int",
    "integer",
    "unsignedInt",
    "unsignedShort",
    "double",
    "string",
    "boolean",
    "dateTime",
)
RULES: tuple[str, ...] = (
    "equalTo",
    "greaterThan",
    "lessThan",
    "greaterOrEqual",
    "lessOrEqual",
    "notEqualTo",
)
_INT = re.compile(r"[+-]?\d+")
_DOUBLE = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|[+-]?INF|NaN")
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
MAX_INT_DIGITS = 20  # the longest integer literal read [digits] (2**63 has 19)
MAX_EXPRESSION_CHARS = 500_000  # [characters] of `${...}` evaluated by one load, in all
MAX_SHOWN = 40  # [characters] of a bad value quoted in a message
_INT_RANGE: Mapping[str, tuple[int, int]] = {
    "unsignedInt": (0, 2**32 - 1),
    "unsignedShort": (0, 2**16 - 1),
}


@dataclass(frozen=True, slots=True)
class ValueConstraint:
    rule: Rule
    value: str  # as written: a literal, `$name` or `${...}` (resolved when checked)


@dataclass(frozen=True, slots=True)
class ConstraintGroup:
    constraints: tuple[ValueConstraint, ...]  # all must hold


@dataclass(frozen=True, slots=True)
class ParameterInfo:
    """A declared parameter, as written (for sweeps and messages)."""

    name: str
    type: ParameterType
    default: str  # the declared value as written (may be `$name` or `${...}`)
    constraint_groups: tuple[ConstraintGroup, ...]  # any one fully satisfied; () = any value
    line: int  # where it is declared


class Budget:
    """The expression text one load may evaluate, in all [characters]: each `${...}` spends
    its length (a catalog entry's expressions again at every reference), so that a file of
    many long expressions cannot make a load take minutes."""

    __slots__ = ("left",)

    def __init__(self, left: int = MAX_EXPRESSION_CHARS) -> None:
        self.left = left

    def spend(self, chars: int) -> None:
        """Takes `chars` from the budget; `ResolveError` once it is spent."""
        self.left -= chars
        if self.left < 0:
            raise ResolveError(f"the file's expressions add up to over {MAX_EXPRESSION_CHARS} "
                               f"characters evaluated (at most {MAX_EXPRESSION_CHARS})")


class Scope:
    """Parameter values by name, with the enclosing scope's as fallback; the expression
    budget of the load (shared with the enclosing scope's)."""

    __slots__ = ("budget", "parent", "values")

    def __init__(self, values: dict[str, ParamValue], parent: Scope | None = None,
                 budget: Budget | None = None) -> None:
        self.values = values
        self.parent = parent
        inherited: Budget | None = parent.budget if parent is not None else None
        self.budget: Budget = budget or inherited or Budget()

    def get(self, name: str) -> ParamValue | None:
        scope: Scope | None = self
        while scope is not None:
            if name in scope.values:
                return scope.values[name]
            scope = scope.parent
        return None


class ResolveError(ValueError):
    """A value cannot be resolved or converted: the message says why (one line)."""


def brief(value: object) -> str:
    """`repr(value)`, cut to MAX_SHOWN characters (a message stays one short line)."""
    text = repr(value)
    return text if len(text) <= MAX_SHOWN else text[: MAX_SHOWN - 3] + "..."


def _expression_value(name: str, scope: Scope) -> Value:
    value = scope.get(name)
    if value is None:
        raise ExpressionError(f"unresolved parameter reference ${name}")
    if isinstance(value, bool | float):
        return value
    if isinstance(value, int):
        return float(value)
    if _DOUBLE.fullmatch(value.strip()):
        return float(value.strip().replace("INF", "inf"))  # the evaluator refuses non-finite
    raise ExpressionError(f"parameter ${name} is not a number ({brief(value)})")


def resolve(raw: str, scope: Scope) -> ParamValue:
    """The value of an attribute as written: `${expr}` evaluated, `$name` looked up, else
    the text itself; `ResolveError` for an unresolved reference or a bad expression."""
    if raw.startswith("${"):
        scope.budget.spend(len(raw))
        if not raw.endswith("}"):
            raise ResolveError(f"expression {brief(raw)} lacks its closing brace")
        try:
            return evaluate(raw[2:-1], lambda n: _expression_value(n, scope))
        except ExpressionError as exc:
            shown = raw if len(raw) <= MAX_SHOWN else brief(raw)
            raise ResolveError(f"expression {shown}: {exc}") from None
    if raw.startswith("$"):
        name = raw[1:]
        if not _NAME.fullmatch(name):
            raise ResolveError(f"bad parameter reference {brief(raw)}")
        value = scope.get(name)
        if value is None:
            raise ResolveError(f"unresolved parameter reference {raw}")
        return value
    return raw


def to_float(value: ParamValue) -> float:
    """A finite number from a resolved value; `ResolveError` when it is not one (`INF`,
    `NaN` and literals beyond a double's range, like `1e999`, are refused)."""
    if isinstance(value, bool):
        raise ResolveError(f"expected a number, got {str(value).lower()}")
    if isinstance(value, int | float):
        number = float(value)
    else:
        text = value.strip()
        if not _DOUBLE.fullmatch(text):
            raise ResolveError(f"expected a number, got {brief(value)}")
        number = float(text.replace("INF", "inf"))
    if not math.isfinite(number):
        raise ResolveError(f"expected a finite number, got {brief(value)}")
    return number


def to_int(value: ParamValue) -> int:
    """An integer from a resolved value: an expression's double result is rounded half
    away from zero; a written value must be an integer literal."""
    if isinstance(value, bool):
        raise ResolveError(f"expected an integer, got {str(value).lower()}")
    if isinstance(value, int):
        return value
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ResolveError(f"expected an integer, got {value}")
        return math.floor(abs(value) + 0.5) * (1 if value >= 0 else -1)
    text = value.strip()
    if not _INT.fullmatch(text):
        raise ResolveError(f"expected an integer, got {brief(value)}")
    digits = len(text.lstrip("+-"))
    if digits > MAX_INT_DIGITS:
        raise ResolveError(f"an integer of {digits} digits: at most {MAX_INT_DIGITS}")
    return int(text)


def to_bool(value: ParamValue) -> bool:
    """A boolean from a resolved value (`true`/`false`/`1`/`0`)."""
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.strip() in ("true", "false", "1", "0"):
        return value.strip() in ("true", "1")
    raise ResolveError(f"expected true or false, got {brief(value)}")


def to_str(value: ParamValue) -> str:
    """Text from a resolved value (numbers without a trailing `.0`, booleans lower case)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return fmt(value)
    return str(value)


def convert(value: ParamValue, ptype: ParameterType) -> ParamValue:
    """A resolved value as a parameter of type `ptype`; `ResolveError` if it is not one."""
    if ptype == "double":
        return to_float(value)
    if ptype in ("int", "integer", "unsignedInt", "unsignedShort"):
        number = to_int(value)
        low, high = _INT_RANGE.get(ptype, (-(2**31), 2**31 - 1))
        if not low <= number <= high:
            raise ResolveError(f"{number} is out of range for {ptype} [{low}, {high}]")
        return number
    if ptype == "boolean":
        return to_bool(value)
    if ptype == "dateTime":
        text = to_str(value)
        try:
            datetime.fromisoformat(text)
        except ValueError:
            raise ResolveError(f"expected a dateTime, got {brief(text)}") from None
        return text
    return to_str(value)


class DeclarationWarning(UserWarning):
    """A declaration esmini accepts and avsim follows, but which is likely a mistake (a
    parameter declared twice); the message is one line `<file>: <key>: <problem>`."""


def declared_name(raw: str | None) -> str | None:
    """A declaration's parameter name: a leading `$` (as 1.0-era files write `name="$owner"`)
    is not part of it, so `$owner` refers to it, as esmini reads it."""
    return raw[1:] if raw is not None and raw.startswith("$") else raw


def parse_declarations(node: Node | None) -> tuple[ParameterInfo, ...]:
    """The ParameterDeclaration children of a ParameterDeclarations element, as written; a
    name declared again replaces the earlier declaration (`DeclarationWarning`)."""
    if node is None:
        return ()
    infos: list[ParameterInfo] = []
    for decl in node.all("ParameterDeclaration"):
        name = declared_name(decl.attrs.get("name"))
        ptype = decl.attrs.get("parameterType")
        default = decl.attrs.get("value")
        if name is None or ptype is None or default is None:
            missing = "name" if name is None else "parameterType" if ptype is None else "value"
            raise decl.error(f"missing attribute {missing}")
        if len(name) > MAX_NAME_CHARS:
            raise decl.error(f"name: {len(name)} characters: at most {MAX_NAME_CHARS}")
        if ptype not in PARAMETER_TYPES:
            known = ", ".join(PARAMETER_TYPES)
            raise decl.error(f"parameterType {brief(ptype)} is not one of {known}")
        if any(i.name == name for i in infos):  # esmini's own catalogs do this
            infos = [i for i in infos if i.name != name]
            warnings.warn(DeclarationWarning(
                f"{decl.file}: {decl.key}: parameter {name} declared twice: the later "
                "declaration is used"), stacklevel=2)
        groups: list[ConstraintGroup] = []
        for group in decl.all("ConstraintGroup"):
            constraints: list[ValueConstraint] = []
            for vc in group.all("ValueConstraint"):
                rule = vc.attrs.get("rule")
                value = vc.attrs.get("value")
                if rule not in RULES or value is None:
                    raise vc.error(f"needs rule (one of {', '.join(RULES)}) and value")
                constraints.append(ValueConstraint(rule, value))  # type: ignore[arg-type]
            groups.append(ConstraintGroup(tuple(constraints)))
        infos.append(ParameterInfo(name, ptype, default, tuple(groups), decl.line))  # type: ignore[arg-type]
    return tuple(infos)


def _holds(rule: str, value: ParamValue, bound: ParamValue) -> bool:
    if isinstance(value, bool):
        if rule not in ("equalTo", "notEqualTo"):
            raise ResolveError(f"{rule} cannot compare booleans")
        return (value == to_bool(bound)) == (rule == "equalTo")
    if isinstance(value, str):
        left, right = to_str(value), to_str(bound)
        if rule == "equalTo":
            return left == right
        if rule == "notEqualTo":
            return left != right
        raise ResolveError(f"{rule} cannot compare text")
    a, b = float(value), to_float(bound)
    return {
        "equalTo": a == b,
        "notEqualTo": a != b,
        "greaterThan": a > b,
        "lessThan": a < b,
        "greaterOrEqual": a >= b,
        "lessOrEqual": a <= b,
    }[rule]


def _shown(raw: str, value: ParamValue, bound: ParamValue) -> str:
    """The constraint's value as compared (a number without a trailing `.0`), followed by
    the reference or expression it came from."""
    text = to_str(bound) if isinstance(value, str | bool) else fmt(to_float(bound))
    return f"{text} ({raw})" if raw.startswith("$") else text


def check_constraints(info: ParameterInfo, value: ParamValue, scope: Scope, where: Node) -> None:
    """`ScenarioError` (at `where`) when `value` satisfies none of the constraint groups."""
    broken: list[str] = []
    for group in info.constraint_groups:
        failed: list[str] = []
        for vc in group.constraints:
            try:
                bound = resolve(vc.value, scope)
                ok = _holds(vc.rule, value, bound)
            except ResolveError as exc:
                raise where.error(f"parameter {info.name}: constraint {vc.rule}: {exc}") from None
            if not ok:
                failed.append(f"{vc.rule} {_shown(vc.value, value, bound)}")
        if not failed:
            return
        broken.append(" and ".join(failed))
    if broken:
        what = broken[0] if len(broken) == 1 else "every constraint group: " + "; ".join(broken)
        raise where.error(f"parameter {info.name} = {to_str(value)}: breaks {what}")


def evaluate_declarations(
    node: Node | None,
    parent: Scope | None,
    overrides: Mapping[str, str],
    *,
    file: str,
    overrides_from: str = "override",
    budget: Budget | None = None,
) -> Scope:
    """The scope of the parameters declared under `node` (a ParameterDeclarations element),
    each value `overrides[name]` if given, else its declared default; references resolve in
    this scope (earlier parameters) then in `parent`; expressions spend `budget` (None: the
    parent's, or a new one). Checks types and constraints; raises
    `ScenarioError` for an unknown override name, a badly typed value or a broken constraint.
    """
    infos = parse_declarations(node)
    known = {i.name for i in infos}
    for name in overrides:
        if name not in known:
            listing = ", ".join(sorted(known)) or "none"
            problem = f"unknown parameter {name}; declared: {listing}"
            raise ScenarioError(file, f"({overrides_from}s)", problem)
    scope = Scope({}, parent, budget)
    assert node is not None or not infos
    found = node.all("ParameterDeclaration") if node is not None else []
    decls = {declared_name(d.attrs.get("name")): d for d in found}
    for info in infos:  # each name's last declaration: `parse_declarations`
        decl = decls[info.name]
        raw = overrides.get(info.name, info.default)
        source = f" ({overrides_from} {brief(raw)})" if info.name in overrides else ""
        try:
            value = convert(resolve(raw, scope), info.type)
        except ResolveError as exc:
            raise decl.error(f"parameter {info.name}{source}: {exc}") from None
        scope.values[info.name] = value
    for info in infos:
        check_constraints(info, scope.values[info.name], scope, decls[info.name])
    return scope
