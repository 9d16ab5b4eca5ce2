"""Fuzzers of the OpenSCENARIO loaders: the expression language (random text, random token
sequences), an ALKS file's attributes and its vehicle catalog's set to hostile values
(`1e999`, `NaN`, integers of thousands of digits, random expressions). The outcome is a value
or an `ExpressionError` for an expression, a scenario or the one-line `ScenarioError` for a
file; never another exception. (`tests/avsim/scenario/test_fuzz.py` mutates the ALKS files'
elements.)"""

from __future__ import annotations

import math
import shutil
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from avsim.scenario.errors import ScenarioError
from avsim.scenario.load import load_scenario
from avsim.scenario.openscenario.expressions import FUNCTIONS, ExpressionError, evaluate
from tests.fuzzing import FUZZ, scaled

pytestmark = pytest.mark.fuzz

ALKS = Path(__file__).parents[3] / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
CUT_IN = "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
VEHICLES = Path("catalogs") / "vehicles" / "vehicle_catalog.xosc"

TOKENS = st.sampled_from([
    "1", "0", "2.5", "1e308", "1e999", "1e-320", ".5", "9" * 400, "$a", "$b", "$missing",
    "true", "false", "not", "and", "or", "+", "-", "*", "/", "%", "(", ")", ",", "==",
    "!=", "<", "<=", ">", ">=", "__import__", "eval", "'", "\"", "$", "${", "}", " ",
    *FUNCTIONS,
])


def _lookup(name: str) -> float | bool:
    values: dict[str, float | bool] = {"a": 1e308, "b": True}
    if name not in values:
        raise ExpressionError(f"unresolved parameter reference ${name}")
    return values[name]


def _evaluates_or_refuses(text: str) -> None:
    try:
        value = evaluate(text, _lookup)
    except ExpressionError as exc:
        assert "\n" not in str(exc)
        return
    assert isinstance(value, bool) or math.isfinite(value)


@FUZZ
@given(st.lists(TOKENS, max_size=60))
def test_random_token_sequences_evaluate_or_refuse(tokens: list[str]) -> None:
    _evaluates_or_refuses(" ".join(tokens))


@FUZZ
@given(st.text(alphabet="0123456789.eE+-*/%() ,<>=!$abnotrundfilsgcqpwmx_\t", max_size=80))
def test_random_expression_text_evaluates_or_refuses(text: str) -> None:
    _evaluates_or_refuses(text)


@FUZZ
@given(st.integers(min_value=0, max_value=300), st.sampled_from(["(", "-", "not ", "sin("]))
def test_deep_nesting_is_refused_not_a_recursion_error(depth: int, opener: str) -> None:
    closer = ")" if "(" in opener else ""
    _evaluates_or_refuses(opener * depth + "1" + closer * depth)


HOSTILE = st.one_of(
    st.sampled_from(["1e999", "-1e999", "NaN", "INF", "-INF", "1" * 5000, "-" + "9" * 30,
                     "${floor(1e308*10)}", "${round(1e999)}", "${sin(1e999)}", "${1/0}",
                     "${" + "(" * 150 + "1" + ")" * 150 + "}", "${" + "+".join("1" * 6000) + "}",
                     "1e9", "-1e9", "0", "-0.0", "x" * 1000, "$missing", "${", "}", ""]),
    st.builds(lambda t: "${" + " ".join(t) + "}", st.lists(TOKENS, max_size=12)),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers().map(str),
)


@pytest.fixture(scope="module")
def alks_copy() -> Iterator[Path]:
    """A writable copy of the ALKS set (a scenario with its catalogs and road)."""
    with tempfile.TemporaryDirectory() as folder:
        target = Path(folder) / "alks"
        shutil.copytree(ALKS, target, ignore=shutil.ignore_patterns("openPASS_Resources"))
        yield target


def _set_attribute(source: Path, target: Path, index: int, value: str) -> None:
    """`target`: `source` with one attribute (the `index`-th of all, cyclically) set."""
    tree = ET.parse(source)
    slots = [(e, name) for e in tree.getroot().iter() for name in sorted(e.attrib)]
    element, name = slots[index % len(slots)]
    element.attrib[name] = value
    tree.write(target, encoding="unicode")


def _loads_or_one_line_error(path: Path) -> None:
    try:
        load_scenario(path)
    except ScenarioError as exc:
        assert "\n" not in str(exc)


@scaled(40)
@given(st.integers(min_value=0, max_value=10_000), HOSTILE)
def test_a_hostile_attribute_in_the_scenario_loads_or_is_one_line(
        alks_copy: Path, index: int, value: str) -> None:
    source, target = ALKS / CUT_IN, alks_copy / CUT_IN
    try:
        _set_attribute(source, target, index, value)
        _loads_or_one_line_error(target)
    finally:
        shutil.copyfile(source, target)


@scaled(40)
@given(st.integers(min_value=0, max_value=10_000), HOSTILE)
def test_a_hostile_attribute_in_a_catalog_loads_or_is_one_line(
        alks_copy: Path, index: int, value: str) -> None:
    source, target = ALKS / VEHICLES, alks_copy / VEHICLES
    try:
        _set_attribute(source, target, index, value)
        _loads_or_one_line_error(alks_copy / CUT_IN)
    finally:
        shutil.copyfile(source, target)
