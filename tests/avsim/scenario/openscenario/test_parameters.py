"""ParameterDeclarations: types, references to earlier parameters, constraint groups,
overrides, and attribute resolution."""

from __future__ import annotations

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.openscenario.parameters import (
    DeclarationWarning,
    ResolveError,
    Scope,
    evaluate_declarations,
    resolve,
    to_int,
)
from avsim.scenario.openscenario.xmlread import parse_xml_bytes


def declarations(body: str, overrides: dict[str, str] | None = None) -> dict[str, object]:
    doc = f"<ParameterDeclarations>\n{body}\n</ParameterDeclarations>".encode()
    node = parse_xml_bytes(doc, "t.xosc")
    return dict(evaluate_declarations(node, None, overrides or {}, file="t.xosc").values)


def failure(body: str, overrides: dict[str, str] | None = None) -> str:
    with pytest.raises(ScenarioError) as info:
        declarations(body, overrides)
    return str(info.value)


def decl(name: str, ptype: str, value: str, groups: str = "") -> str:
    return (
        f'<ParameterDeclaration name="{name}" parameterType="{ptype}" value="{value}">'
        f"{groups}</ParameterDeclaration>"
    )


def test_types() -> None:
    values = declarations(
        "\n".join(
            [
                decl("i", "integer", "-7"),
                decl("j", "int", "+3"),
                decl("u", "unsignedInt", "4294967295"),
                decl("s", "unsignedShort", "7"),
                decl("d", "double", "1e3"),
                decl("b", "boolean", "false"),
                decl("b1", "boolean", "1"),
                decl("t", "dateTime", "2021-07-09T10:00:00"),
                decl("x", "string", "hello"),
            ]
        )
    )
    assert values == {
        "i": -7,
        "j": 3,
        "u": 4294967295,
        "s": 7,
        "d": 1000.0,
        "b": False,
        "b1": True,
        "t": "2021-07-09T10:00:00",
        "x": "hello",
    }


@pytest.mark.parametrize(
    ("ptype", "value", "problem"),
    [
        ("integer", "1.5", "expected an integer, got '1.5'"),
        ("unsignedShort", "70000", "70000 is out of range for unsignedShort [0, 65535]"),
        ("unsignedInt", "-1", "-1 is out of range for unsignedInt [0, 4294967295]"),
        ("double", "fast", "expected a number, got 'fast'"),
        ("boolean", "yes", "expected true or false, got 'yes'"),
        ("dateTime", "soon", "expected a dateTime, got 'soon'"),
    ],
)
def test_badly_typed_defaults(ptype: str, value: str, problem: str) -> None:
    assert failure(decl("p", ptype, value)) == (
        f"t.xosc: line 2: /ParameterDeclarations/ParameterDeclaration[p]: parameter p: {problem}"
    )


def test_references_and_expressions_use_earlier_parameters() -> None:
    values = declarations(
        "\n".join(
            [
                decl("kph", "double", "72"),
                decl("mps", "double", "${$kph / 3.6}"),
                decl("copy", "double", "$mps"),
                decl("lanes", "integer", "${$kph / 10}"),  # 7.2 rounds to 7
                decl("ok", "boolean", "${$mps &gt; 10 and not $kph == 0}"),
            ]
        )
    )
    assert values == {"kph": 72.0, "mps": 20.0, "copy": 20.0, "lanes": 7, "ok": True}


def test_later_parameters_are_not_visible() -> None:
    text = failure(decl("a", "double", "$b") + decl("b", "double", "1"))
    assert text.endswith("ParameterDeclaration[a]: parameter a: unresolved parameter reference $b")


def test_default_must_satisfy_its_constraints() -> None:
    groups = '<ConstraintGroup><ValueConstraint rule="lessThan" value="5"/></ConstraintGroup>'
    assert failure(decl("p", "double", "7.5", groups)).endswith(
        "parameter p = 7.5: breaks lessThan 5"
    )


def test_all_constraints_of_a_group_and_any_group() -> None:
    groups = (
        "<ConstraintGroup>"
        '<ValueConstraint rule="greaterOrEqual" value="0"/>'
        '<ValueConstraint rule="lessOrEqual" value="10"/>'
        "</ConstraintGroup>"
        '<ConstraintGroup><ValueConstraint rule="equalTo" value="100"/></ConstraintGroup>'
    )
    body = decl("p", "double", "5", groups)
    assert declarations(body) == {"p": 5.0}
    assert declarations(body, {"p": "100"}) == {"p": 100.0}
    assert failure(body, {"p": "11"}).endswith(
        "parameter p = 11: breaks every constraint group: lessOrEqual 10; equalTo 100"
    )
    assert failure(body, {"p": "-1"}).endswith(
        "parameter p = -1: breaks every constraint group: greaterOrEqual 0; equalTo 100"
    )


def test_string_constraints() -> None:
    groups = (
        '<ConstraintGroup><ValueConstraint rule="equalTo" value="-3"/></ConstraintGroup>'
        '<ConstraintGroup><ValueConstraint rule="equalTo" value="-4"/></ConstraintGroup>'
    )
    body = decl("lane", "string", "-3", groups)
    assert declarations(body, {"lane": "-4"}) == {"lane": "-4"}
    assert failure(body, {"lane": "-5"}).endswith(
        "parameter lane = -5: breaks every constraint group: equalTo -3; equalTo -4"
    )
    ordered = '<ConstraintGroup><ValueConstraint rule="lessThan" value="b"/></ConstraintGroup>'
    assert failure(decl("s", "string", "a", ordered)).endswith(
        "parameter s: constraint lessThan: lessThan cannot compare text"
    )


def test_boolean_constraints() -> None:
    groups = '<ConstraintGroup><ValueConstraint rule="notEqualTo" value="false"/></ConstraintGroup>'
    body = decl("on", "boolean", "true", groups)
    assert declarations(body) == {"on": True}
    assert failure(body, {"on": "0"}).endswith("parameter on = false: breaks notEqualTo false")


def test_constraint_referencing_a_later_parameter() -> None:
    groups = '<ConstraintGroup><ValueConstraint rule="lessThan" value="$max"/></ConstraintGroup>'
    body = decl("v", "double", "3", groups) + decl("max", "double", "4")
    assert declarations(body) == {"v": 3.0, "max": 4.0}
    assert failure(body, {"max": "2"}).endswith("parameter v = 3: breaks lessThan 2 ($max)")


def test_unknown_override() -> None:
    assert failure(decl("a", "double", "1"), {"b": "2"}) == (
        "t.xosc: (overrides): unknown parameter b; declared: a"
    )


def test_override_of_the_wrong_type() -> None:
    assert failure(decl("n", "integer", "1"), {"n": "two"}).endswith(
        "parameter n (override 'two'): expected an integer, got 'two'"
    )


def test_overrides_may_be_expressions() -> None:
    body = decl("a", "double", "1") + decl("b", "double", "2")
    assert declarations(body, {"b": "${$a * 10}"}) == {"a": 1.0, "b": 10.0}


def test_resolve() -> None:
    scope = Scope({"x": 2.0, "name": "car"}, Scope({"outer": 5}))
    assert resolve("plain", scope) == "plain"
    assert resolve("$name", scope) == "car"
    assert resolve("$outer", scope) == 5
    assert resolve("${$x * $outer}", scope) == 10.0
    with pytest.raises(ResolveError, match=r"unresolved parameter reference \$nope"):
        resolve("$nope", scope)
    with pytest.raises(ResolveError, match="is not a number"):
        resolve("${$name + 1}", scope)
    with pytest.raises(ResolveError, match="lacks its closing brace"):
        resolve("${1 + 2", scope)


def test_to_int_rounds_expression_results_half_away_from_zero() -> None:
    assert to_int(2.5) == 3
    assert to_int(-2.5) == -3
    assert to_int(2.4999) == 2
    with pytest.raises(ResolveError):
        to_int("2.0")


def test_a_parameter_declared_twice_takes_the_later_declaration_with_a_warning() -> None:
    body = (decl("mass", "double", "1000") + decl("length", "double", "4")
            + decl("mass", "double", "2000", '<ConstraintGroup><ValueConstraint '
                   'rule="greaterThan" value="1500"/></ConstraintGroup>')
            + decl("load", "double", "${$mass / 4}"))
    with pytest.warns(DeclarationWarning, match=r"t\.xosc: line \d+: .*: parameter mass "
                      "declared twice: the later declaration is used"):
        values = declarations(body)
    assert values == {"length": 4.0, "mass": 2000.0, "load": 500.0}
