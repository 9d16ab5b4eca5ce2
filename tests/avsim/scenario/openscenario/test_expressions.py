"""The `${...}` expression evaluator: precedence, unary minus, functions, booleans, errors,
and a property test against a reference computed from random expression trees."""

from __future__ import annotations

import math
from dataclasses import dataclass

import pytest
from hypothesis import given
from hypothesis import strategies as st

from avsim.scenario.openscenario.expressions import ExpressionError, Value, evaluate

PARAMS: dict[str, Value] = {"a": 2.0, "b": -3.0, "speed_kph": 36.0, "flag": True}


def ev(text: str) -> Value:
    def lookup(name: str) -> Value:
        if name not in PARAMS:
            raise ExpressionError(f"unresolved parameter reference ${name}")
        return PARAMS[name]

    return evaluate(text, lookup)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("1 + 2 * 3", 7.0),
        ("(1 + 2) * 3", 9.0),
        ("10 - 4 - 3", 3.0),
        ("2 * 3 / 4", 1.5),
        ("7 % 4", 3.0),
        ("-7 % 4", -3.0),
        ("-2 * 3", -6.0),
        ("--2", 2.0),
        ("-(1 + 2)", -3.0),
        ("2 * -3", -6.0),
        ("$a * -$b", 6.0),
        ("$speed_kph / 3.6", 10.0),
        ("1.5e1 + .5", 15.5),
        ("30 + (-10.0 * (-20.0 / 3.6))", 30 + (-10.0 * (-20.0 / 3.6))),
        ("round(2.5)", 3.0),
        ("round(-2.5)", -3.0),
        ("floor(-1.5)", -2.0),
        ("ceil(1.2)", 2.0),
        ("sqrt(16)", 4.0),
        ("pow(2, 10)", 1024.0),
        ("sin(0) + cos(0)", 1.0),
        ("tan(0)", 0.0),
        ("asin(1)", math.pi / 2),
        ("acos(1)", 0.0),
        ("atan(1)", math.pi / 4),
        ("sign(-4) + sign(0) + sign(2)", -1.0 + 0.0 + 1.0),
        ("abs($b)", 3.0),
        ("max(1, $a) + min(1, $a)", 3.0),
        ("2 * sqrt($b * $b) / ($speed_kph / 3.6)", 0.6),
    ],
)
def test_arithmetic(text: str, expected: float) -> None:
    assert ev(text) == pytest.approx(expected)


def test_nesting_up_to_the_limit() -> None:
    assert ev("(" * 99 + "1" + ")" * 99) == 1.0
    assert ev("-" * 99 + "1") == -1.0


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("1 < 2", True),
        ("2 <= 1", False),
        ("1 + 1 == 2", True),
        ("1 != 1", False),
        ("3 > 2 and 2 > 1", True),
        ("1 > 2 or 2 > 1", True),
        ("not 1 > 2", True),
        ("not true or true", True),
        ("not (true or true)", False),
        ("true or false and false", True),  # and binds tighter than or
        ("$flag and $a >= 2", True),
    ],
)
def test_booleans(text: str, expected: bool) -> None:
    assert ev(text) is expected


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("1 +", "expected a value at 3, found the end"),
        ("(1 + 2", "expected ')' at 6, found the end"),
        ("1 2", "unexpected '2' at 2"),
        ("1 / 0", "division by zero"),
        ("1 % 0", "modulo by zero"),
        ("$nope + 1", "unresolved parameter reference $nope"),
        ("foo(1)", "unknown name 'foo' at 0"),
        ("pow(2)", "pow takes 2 argument(s), got 1"),
        ("sqrt(-1)", "sqrt: argument out of range"),
        ("asin(2)", "asin: argument out of range"),
        ("1 + true", "+ needs a number, got a boolean"),
        ("1 and true", "and needs a boolean, got a number"),
        ("1 # 2", "unexpected character '#' at 2"),
        ("pow(10, 400)", "pow: argument out of range"),
        ("", "expected a value at 0, found the end"),
        ("(" * 101 + "1" + ")" * 101, "nested more than 100 deep"),
        ("-" * 101 + "1", "nested more than 100 deep"),
        ("not " * 101 + "true", "nested more than 100 deep"),
    ],
)
def test_errors(text: str, problem: str) -> None:
    with pytest.raises(ExpressionError) as info:
        ev(text)
    assert str(info.value) == problem


# --- property test: random trees, rendered, evaluated, compared with a direct computation


@dataclass(frozen=True)
class Num:
    value: float


@dataclass(frozen=True)
class Ref:
    name: str


@dataclass(frozen=True)
class Neg:
    inner: Tree


@dataclass(frozen=True)
class Bin:
    op: str
    left: Tree
    right: Tree


Tree = Num | Ref | Neg | Bin
_LEVEL = {"+": 1, "-": 1, "*": 2, "/": 2, "%": 2}


def render(tree: Tree, *, spaced: bool) -> str:
    """Fully parenthesised text, so precedence does not matter for the reference."""
    gap = " " if spaced else ""
    if isinstance(tree, Num):
        return repr(tree.value)
    if isinstance(tree, Ref):
        return f"${tree.name}"
    if isinstance(tree, Neg):
        return f"-({render(tree.inner, spaced=spaced)})"
    left, right = render(tree.left, spaced=spaced), render(tree.right, spaced=spaced)
    return f"({left}{gap}{tree.op}{gap}{right})"


def reference(tree: Tree) -> float:
    if isinstance(tree, Num):
        return tree.value
    if isinstance(tree, Ref):
        value = PARAMS[tree.name]
        assert isinstance(value, float)
        return value
    if isinstance(tree, Neg):
        return -reference(tree.inner)
    a, b = reference(tree.left), reference(tree.right)
    if tree.op in "/%" and b == 0:
        raise ZeroDivisionError
    return {
        "+": lambda: a + b,
        "-": lambda: a - b,
        "*": lambda: a * b,
        "/": lambda: a / b,
        "%": lambda: math.fmod(a, b),
    }[tree.op]()


numbers = st.floats(min_value=0, max_value=1000, allow_nan=False).map(lambda v: Num(round(v, 3)))
leaves = numbers | st.sampled_from([Ref("a"), Ref("b"), Ref("speed_kph")])
trees = st.recursive(
    leaves,
    lambda inner: (
        st.builds(Neg, inner) | st.builds(Bin, st.sampled_from(sorted(_LEVEL)), inner, inner)
    ),
    max_leaves=12,
)


@given(trees, st.booleans())
def test_agrees_with_reference(tree: Tree, spaced: bool) -> None:
    text = render(tree, spaced=spaced)
    try:
        expected = reference(tree)
    except ZeroDivisionError:
        with pytest.raises(ExpressionError):
            ev(text)
        return
    if not math.isfinite(expected):
        return
    assert ev(text) == pytest.approx(expected, rel=1e-12, abs=1e-12)


def _precedence_text(tree: Tree) -> str:
    """Minimal parentheses from precedence (left-associative), unary minus kept tight."""
    if isinstance(tree, Num | Ref):
        return render(tree, spaced=True)
    if isinstance(tree, Neg):
        inner = _precedence_text(tree.inner)
        return f"-{inner}" if isinstance(tree.inner, Num | Ref | Neg) else f"-({inner})"
    level = _LEVEL[tree.op]
    left = _precedence_text(tree.left)
    if isinstance(tree.left, Bin) and _LEVEL[tree.left.op] < level:
        left = f"({left})"
    right = _precedence_text(tree.right)
    if isinstance(tree.right, Bin) and _LEVEL[tree.right.op] <= level:
        right = f"({right})"
    return f"{left} {tree.op} {right}"


@given(trees)
def test_precedence_without_parentheses(tree: Tree) -> None:
    text = _precedence_text(tree)
    try:
        expected = reference(tree)
    except ZeroDivisionError:
        return
    if not math.isfinite(expected):
        return
    assert ev(text) == pytest.approx(expected, rel=1e-9, abs=1e-9)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("pi", math.pi),
        ("-pi/2", -math.pi / 2),
        ("$speed_kph * pi / 180", 36.0 * math.pi / 180),
        ("2 * pi", 2 * math.pi),
        ("e", math.e),
        ("-e", -math.e),
        ("cos(pi)", -1.0),
        ("round(pi * 100) / 100", 3.14),
        ("pi > 3 and e < 3", True),
    ],
)
def test_constants_pi_and_e_as_esmini_defines_them(text: str, expected: Value) -> None:
    assert ev(text) == expected


@pytest.mark.parametrize("text", ["pie", "PI", "pi(1)", "pi pi", "tau"])
def test_other_names_are_still_refused(text: str) -> None:
    with pytest.raises(ExpressionError):
        ev(text)
