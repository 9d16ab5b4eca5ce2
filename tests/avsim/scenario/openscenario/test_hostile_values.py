"""Hostile values in an OpenSCENARIO file: expressions that overflow or are huge, numbers
that are not finite or far out of the format's bounds, integers of thousands of digits,
degenerate or huge bounding boxes, entities placed inside each other, huge names. Each is
the one-line `ScenarioError` (an `ExpressionError` from the evaluator alone), with bounded
work."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.load import load_scenario
from avsim.scenario.openscenario import expressions
from avsim.scenario.openscenario.expressions import (
    MAX_DEPTH,
    MAX_LENGTH,
    ExpressionError,
    evaluate,
    tokenize,
)
from avsim.scenario.openscenario.limits import MAX_NAME_CHARS
from avsim.scenario.openscenario.parameters import MAX_EXPRESSION_CHARS

ALKS = Path(__file__).parents[3] / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
CUT_IN = "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"
VEHICLES = Path("catalogs") / "vehicles" / "vehicle_catalog.xosc"


def _one(_: str) -> float:
    return 1.0


@pytest.mark.parametrize(("text", "problem"), [
    ("floor(1e308*10)", "*: result out of range"),
    ("round(1e999)", "number 1e999 at 6: result out of range"),
    ("sin(1e999)", "result out of range"),
    ("sin(1e308 * 1e308)", "*: result out of range"),
    ("pow(10, 400)", "pow: argument out of range"),
    ("1e308 + 1e308", "+: result out of range"),
    ("-1e308 - 1e308", "-: result out of range"),
    ("1e-308 / 1e-308 * 1e308 / 1e-10", "/: result out of range"),
    ("__import__(1)", "unknown name '__import__'"),
])
def test_overflow_and_non_finite_are_expression_errors(text: str, problem: str) -> None:
    with pytest.raises(ExpressionError) as err:
        evaluate(text, _one)
    assert problem in str(err.value)


def test_a_huge_expression_is_refused_before_it_is_tokenized() -> None:
    text = "+".join(["1"] * 1_000_000)  # 2 MB: 54 s to tokenize before the bound
    with pytest.raises(ExpressionError, match=f"1999999 characters long: at most {MAX_LENGTH}"):
        evaluate(text, _one)


class _CountingText(str):
    """A text that counts the characters its slices copy (a quadratic tokenizer copies
    the rest of the text once per token)."""

    copied = 0

    def __getitem__(self, key: object) -> str:
        piece = str.__getitem__(self, key)  # type: ignore[index]
        _CountingText.copied += len(piece)
        return piece


def test_tokenizing_copies_a_bounded_amount_of_text() -> None:
    text = _CountingText(" + ".join(["1.5"] * 1500) + "   ")
    _CountingText.copied = 0
    tokens = tokenize(text)
    assert len(tokens) == 3000  # 1500 numbers, 1499 plus signs, the end
    assert _CountingText.copied <= 2 * len(text)


def test_an_expression_at_the_length_bound_is_evaluated_in_one_pass(
        monkeypatch: pytest.MonkeyPatch) -> None:
    text = "+".join(["$a"] * ((MAX_LENGTH + 1) // 3))
    assert len(text) <= MAX_LENGTH
    looked_up: list[str] = []

    def lookup(name: str) -> float:
        looked_up.append(name)
        return 1.0

    assert evaluate(text, lookup) == len(looked_up) == (MAX_LENGTH + 1) // 3
    taken = 0
    original = expressions._Evaluator.take

    def counting(self: expressions._Evaluator) -> expressions.Token:
        nonlocal taken
        taken += 1
        return original(self)

    monkeypatch.setattr(expressions._Evaluator, "take", counting)
    evaluate(text, lookup)
    assert taken == 2 * ((MAX_LENGTH + 1) // 3) - 1  # each token once


def test_nesting_is_refused_before_anything_is_evaluated() -> None:
    looked_up: list[str] = []

    def lookup(name: str) -> float:
        looked_up.append(name)
        return 1.0

    for text in ("$a + " + "(" * (MAX_DEPTH + 1) + "1" + ")" * (MAX_DEPTH + 1),
                 "$a + " + "-" * (MAX_DEPTH + 1) + "1",
                 "$a + " + "(-" * 51 + "1" + ")" * 51):
        with pytest.raises(ExpressionError, match=f"nested more than {MAX_DEPTH} deep"):
            evaluate(text, lookup)
    assert looked_up == []
    assert evaluate("(" * 50 + "-" * 40 + "1" + ")" * 50, _one) == 1.0


# --- in a scenario file -----------------------------------------------------------------

@pytest.fixture
def tree(tmp_path: Path) -> Path:
    copy = tmp_path / "alks"
    shutil.copytree(ALKS, copy, ignore=shutil.ignore_patterns("openPASS_Resources"))
    return copy


def _refused(tree: Path, old: str, new: str, file: Path = Path(CUT_IN)) -> str:
    path = tree / file
    text = path.read_text(encoding="utf-8-sig")
    assert old in text
    path.write_text(text.replace(old, new), encoding="utf-8")
    with pytest.raises(ScenarioError) as err:
        load_scenario(tree / CUT_IN)
    message = str(err.value)
    assert "\n" not in message and len(message) < 400 + len(str(path))
    return message


SPEED = 'name="Ego_InitSpeed_Ve0_kph" parameterType="double" value="60.0"'
LANE = 'name="CutInVehicle_InitPosition_RelativeLaneId" parameterType="integer" value="-1"'
STOP = '<Condition name="End" delay="10.0"'
START = '<SimulationTimeCondition value="3.0"'


@pytest.mark.parametrize(("old", "new", "problem"), [
    (SPEED, SPEED.replace("60.0", "${floor(1e308*10)}"), "*: result out of range"),
    (SPEED, SPEED.replace("60.0", "${round(1e999)}"), "result out of range"),
    (SPEED, SPEED.replace("60.0", "${sin(1e999)}"), "result out of range"),
    (SPEED, SPEED.replace("60.0", "1e999"), "expected a finite number, got '1e999'"),
    (SPEED, SPEED.replace("60.0", "NaN"), "expected a finite number, got 'NaN'"),
    (SPEED, SPEED.replace("60.0", "-INF"), "expected a finite number"),
    (LANE, LANE.replace("-1", "-" + "1" * 5000), "an integer of 5000 digits: at most 20"),
    (STOP, STOP.replace("10.0", "1e999"), "delay: expected a finite number"),
    (STOP, STOP.replace("10.0", "NaN"), "delay: expected a finite number"),
    (STOP, STOP.replace("10.0", "1e9"), "delay: must be in [0, 7200] s, got 1000000000"),
    (STOP, STOP.replace("10.0", "-1"), "delay: must be in [0, 7200] s, got -1"),
    (START, START.replace("3.0", "7201"), "SimulationTimeCondition: value: must be in [0, 7200]"),
    ('<LanePosition roadId="0" laneId="-4" offset="0.0" s="5.0">',
     '<LanePosition roadId="0" laneId="-4" offset="0.0" s="NaN">', "s: expected a finite"),
    ('<AbsoluteTargetSpeed value="${$Ego_InitSpeed_Ve0_kph / 3.6}" />',
     '<AbsoluteTargetSpeed value="1000" />', "value: must be in [-83.3333, 83.3333] m/s"),
    ('<ScenarioObject name="CutInVehicle">', '<ScenarioObject name="' + "x" * 300_000 + '">',
     f"name: 300000 characters: at most {MAX_NAME_CHARS}"),
])
def test_a_bad_value_in_the_file_is_one_line(tree: Path, old: str, new: str,
                                             problem: str) -> None:
    assert problem in _refused(tree, old, new)


@pytest.mark.parametrize(("size", "problem"), [
    ('width="2.0" length="0" height="1.8"', "length: must be > 0 and <= 30 m, got 0"),
    ('width="-1.8" length="5.0" height="1.8"', "width: must be > 0 and <= 5 m, got -1.8"),
    ('width="2.0" length="1e9" height="1.8"', "length: must be > 0 and <= 30 m, got 1000000000"),
    ('width="2.0" length="5.0" height="6"', "height: must be > 0 and <= 5 m, got 6"),
    ('width="2.0" length="5.0" height="1e999"', "height: expected a finite number"),
])
def test_a_bounding_box_out_of_bounds_is_refused(tree: Path, size: str, problem: str) -> None:
    message = _refused(tree, 'width="2.0" length="5.0" height="1.8"', size, VEHICLES)
    assert "/Dimensions: " + problem in message


def test_an_entity_placed_on_the_ego_is_refused_by_name(tree: Path) -> None:
    message = _refused(tree, 'dLane="$CutInVehicle_InitPosition_RelativeLaneId" ds="${$Cut',
                       'dLane="0" ds="1" x="${$Cut')  # 1 m ahead of the ego, in its lane
    assert message.startswith(f"{tree / CUT_IN}: Entities.CutInVehicle: overlaps the ego (Ego)")


def test_the_expressions_of_one_load_are_bounded_in_all(tree: Path) -> None:
    """Many long expressions, each within MAX_LENGTH: the load stops once it has evaluated
    MAX_EXPRESSION_CHARS of them (not minutes of work)."""
    one = "${" + "+".join(["1"] * 4000) + "}"  # 8,001 characters
    count = MAX_EXPRESSION_CHARS // len(one) + 1
    many = "".join(f'<ParameterDeclaration name="P{k}" parameterType="double" value="{one}"/>'
                   for k in range(count))
    message = _refused(tree, "<ParameterDeclarations>", "<ParameterDeclarations>" + many)
    assert f"ParameterDeclaration[P{count - 1}]: " in message
    assert f"over {MAX_EXPRESSION_CHARS} characters evaluated" in message
