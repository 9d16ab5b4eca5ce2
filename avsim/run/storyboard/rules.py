"""The comparison rules of the storyboard's conditions (OpenSCENARIO's Rule): ints and
strings compare exactly; floats with equalTo / notEqualTo within `FLOAT_EQUAL` (absolute),
the other rules exactly."""

from __future__ import annotations

from collections.abc import Callable, Mapping

from avsim.scenario.openscenario.conditions import ParameterCondition, Rule
from avsim.scenario.openscenario.parameters import ParamValue

FLOAT_EQUAL = 1e-6  # [-] absolute tolerance of equalTo / notEqualTo on floats

_RULES: dict[str, Callable[[float, float], bool]] = {
    "greaterThan": lambda a, b: a > b,
    "lessThan": lambda a, b: a < b,
    "greaterOrEqual": lambda a, b: a >= b,
    "lessOrEqual": lambda a, b: a <= b,
    "equalTo": lambda a, b: a == b,
    "notEqualTo": lambda a, b: a != b,
}


def compare(a: float | int | str, rule: Rule, b: float | int | str) -> bool:
    """`a rule b`; floats equal within `FLOAT_EQUAL`, ints and strings exactly."""
    if isinstance(a, float) or isinstance(b, float):
        fa, fb = float(a), float(b)
        if rule == "equalTo":
            return abs(fa - fb) <= FLOAT_EQUAL
        if rule == "notEqualTo":
            return abs(fa - fb) > FLOAT_EQUAL
    if isinstance(a, str) or isinstance(b, str):
        sa, sb = str(a), str(b)
        return bool(_RULES[rule](sa, sb))  # type: ignore[arg-type]
    return _RULES[rule](a, b)


def _as_type(value: ParamValue, text: str) -> float | int | str:
    if isinstance(value, bool):
        return int(text.strip().lower() == "true")
    if isinstance(value, int):
        return int(text)
    if isinstance(value, float):
        return float(text)
    return text


def value_holds(name: str, rule: Rule, text: str, values: Mapping[str, ParamValue]) -> bool:
    """The value of `name` in `values` (a parameter's, a variable's) against the written
    value `text` read as its type (booleans as 0 / 1; an unknown name: false, as esmini)."""
    if name not in values:
        return False
    value = values[name]
    mine = int(value) if isinstance(value, bool) else value
    return compare(mine, rule, _as_type(value, text))


def parameter_holds(c: ParameterCondition, parameters: Mapping[str, ParamValue]) -> bool:
    """The parameter's value against the written value (`value_holds`)."""
    return value_holds(c.parameter, c.rule, c.value, parameters)
