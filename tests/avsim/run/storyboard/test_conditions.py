"""Each condition kind judged on small hand-made snapshots: every rule, freespace or not,
and the triggering entities' rules "any" and "all"."""

from __future__ import annotations

import math

import pytest

from avsim.run.storyboard.conditions import ConditionContext, Resolved, holds, judge
from avsim.run.storyboard.elements import (
    ElementState,
    TransitionKind,
    TransitionRecord,
)
from avsim.run.storyboard.rules import compare
from avsim.run.storyboard.snapshot import Snapshot
from avsim.scenario.openscenario.conditions import (
    CollisionCondition,
    DistanceCondition,
    EndOfRoadCondition,
    OffroadCondition,
    ParameterCondition,
    ReachPositionCondition,
    RelativeDistanceCondition,
    RelativeSpeedCondition,
    Rule,
    SimulationTimeCondition,
    SpeedCondition,
    StandStillCondition,
    StoryboardElementStateCondition,
    TimeHeadwayCondition,
    TimeToCollisionCondition,
    TraveledDistanceCondition,
)
from avsim.scenario.openscenario.positions import Position, WorldPosition
from tests.avsim.run.storyboard.helpers import condition, context, entity, snapshot

CTX = context()

RULE_CASES = [  # (a, rule, b, expected)
    (2.0, "greaterThan", 1.0, True), (1.0, "greaterThan", 1.0, False),
    (1.0, "lessThan", 2.0, True), (2.0, "lessThan", 2.0, False),
    (1.0, "greaterOrEqual", 1.0, True), (0.9, "greaterOrEqual", 1.0, False),
    (1.0, "lessOrEqual", 1.0, True), (1.1, "lessOrEqual", 1.0, False),
    (1.0 + 5e-7, "equalTo", 1.0, True), (1.0 + 2e-6, "equalTo", 1.0, False),
    (1.0 + 2e-6, "notEqualTo", 1.0, True), (1.0 + 5e-7, "notEqualTo", 1.0, False),
    (3, "equalTo", 3, True), (3, "notEqualTo", 4, True), (3, "equalTo", 4, False),
    ("a", "equalTo", "a", True), ("a", "notEqualTo", "b", True),
]


@pytest.mark.parametrize(("a", "rule", "b", "expected"), RULE_CASES)
def test_rules(a: float, rule: Rule, b: float, expected: bool) -> None:
    assert compare(a, rule, b) is expected


def test_simulation_time() -> None:
    assert holds(SimulationTimeCondition(3.0, "greaterOrEqual"), None, snapshot(t=3.0), CTX)
    assert not holds(SimulationTimeCondition(3.0, "greaterOrEqual"), None, snapshot(t=2.9), CTX)


@pytest.mark.parametrize(("value", "text", "rule", "expected"), [
    (3, "3", "equalTo", True), (3, "2", "greaterThan", True), (2.5, "2.5", "equalTo", True),
    (True, "true", "equalTo", True), (False, "true", "equalTo", False),
    ("fast", "fast", "equalTo", True), ("fast", "slow", "notEqualTo", True),
])
def test_parameter(value: int | float | bool | str, text: str, rule: Rule,
                   expected: bool) -> None:
    ctx = context({"P": value})
    assert holds(ParameterCondition("P", text, rule), None, snapshot(), ctx) is expected
    assert not holds(ParameterCondition("Q", text, rule), None, snapshot(), ctx)


def test_storyboard_element_state() -> None:
    log = [TransitionRecord(1.0, "action", "A", TransitionKind.START, ElementState.RUNNING),
           TransitionRecord(2.0, "action", "A", TransitionKind.END, ElementState.COMPLETE)]
    ctx = ConditionContext({}, {("action", "A"): ElementState.COMPLETE}, log, since=1)
    snap = snapshot()

    def check(state: str, c: ConditionContext = ctx) -> bool:
        return holds(StoryboardElementStateCondition("action", "A", state), None, snap, c)

    assert check("completeState")
    assert not check("runningState")
    assert check("endTransition")
    assert not check("startTransition")  # before the previous evaluation
    assert check("startTransition", ConditionContext({}, ctx.states, log, since=0))
    assert not check("endTransition", ConditionContext({}, ctx.states, log, since=2))


def two(a_x: float = 0.0, b_x: float = 20.0, b_y: float = 0.0, **b: float) -> Snapshot:
    return snapshot(entity("Ego", x=a_x, speed=10.0), entity("Car", x=b_x, y=b_y, **b))


@pytest.mark.parametrize(("dtype", "freespace", "expected"), [
    ("longitudinal", False, 20.0), ("longitudinal", True, 16.0),
    ("lateral", False, 3.0), ("lateral", True, 1.0),
    ("cartesianDistance", False, math.hypot(20.0, 3.0)),
    ("euclidianDistance", True, math.hypot(16.0, 1.0)),
])
def test_relative_distance(dtype: str, freespace: bool, expected: float) -> None:
    snap = two(b_y=3.0)
    for e in ("Ego", "Car"):  # the magnitude: either way round
        other = "Car" if e == "Ego" else "Ego"
        for rule, delta, result in (("lessThan", 0.01, True), ("lessThan", -0.01, False),
                                    ("greaterThan", -0.01, True), ("equalTo", 0.0, True)):
            c = RelativeDistanceCondition(other, dtype, expected + delta, freespace,  # type: ignore[arg-type]
                                          rule, "entity")  # type: ignore[arg-type]
            assert holds(c, e, snap, CTX) is result, (e, rule, delta)


def test_triggering_entities_any_and_all() -> None:
    snap = snapshot(entity("A", speed=5.0), entity("B", speed=15.0))
    fast = SpeedCondition(10.0, "greaterThan")
    assert judge(condition(fast, entities=("A", "B"), rule="any"), snap, CTX) == (True, ("B",))
    assert judge(condition(fast, entities=("A", "B"), rule="all"), snap, CTX) == (False, ("B",))
    assert judge(condition(fast, entities=("B",), rule="all"), snap, CTX) == (True, ("B",))
    slow = SpeedCondition(20.0, "lessThan")
    assert judge(condition(slow, entities=("A", "B"), rule="all"), snap, CTX)[0]
    assert not judge(condition(fast, entities=("Nobody",), rule="any"), snap, CTX)[0]


def resolver(x: float, y: float) -> ConditionContext:
    def resolve(_p: Position, _s: Snapshot) -> Resolved:
        return (x, y, x, y)
    return ConditionContext({}, {}, resolve=resolve)


POINT = WorldPosition(30.0, 4.0, None, None, None, None)


@pytest.mark.parametrize(("dtype", "freespace", "expected"), [
    ("longitudinal", False, 30.0), ("longitudinal", True, 26.5),
    ("lateral", False, 4.0), ("lateral", True, 3.0),
    ("euclidianDistance", False, math.hypot(30.0, 4.0)),
    ("cartesianDistance", True, math.hypot(26.5, 3.0)),
])
def test_distance_to_a_position(dtype: str, freespace: bool, expected: float) -> None:
    ctx = resolver(30.0, 4.0)
    snap = snapshot(entity("Ego"))
    for delta, result in ((0.01, True), (-0.01, False)):
        c = DistanceCondition(POINT, expected + delta, freespace, "lessThan",
                              dtype, "entity")  # type: ignore[arg-type]
        assert holds(c, "Ego", snap, ctx) is result


def test_time_headway() -> None:
    snap = two()  # Ego at 10 m/s, Car 20 m ahead (16 m freespace)
    c = TimeHeadwayCondition("Car", 2.0, False, "greaterOrEqual", "entity", "longitudinal")
    assert holds(c, "Ego", snap, CTX)
    c = TimeHeadwayCondition("Car", 1.6, True, "lessOrEqual", "entity", "longitudinal")
    assert holds(c, "Ego", snap, CTX)
    c = TimeHeadwayCondition("Ego", 100.0, False, "lessThan", "entity", "longitudinal")
    assert not holds(c, "Car", snap, CTX)  # standing
    behind = snapshot(entity("Ego", x=30.0, speed=10.0), entity("Car", x=0.0))
    c = TimeHeadwayCondition("Car", 100.0, False, "lessThan", "entity", "longitudinal")
    assert not holds(c, "Ego", behind, CTX)  # the entity is behind


def test_time_to_collision() -> None:
    snap = two(speed=5.0)  # closing at 5 m/s over 20 m (16 m freespace)
    c = TimeToCollisionCondition("Car", None, 4.0, False, "lessOrEqual", "entity",
                                 "longitudinal")
    assert holds(c, "Ego", snap, CTX)
    assert not holds(TimeToCollisionCondition("Car", None, 3.9, False, "lessOrEqual",
                                              "entity", "longitudinal"), "Ego", snap, CTX)
    assert holds(TimeToCollisionCondition("Car", None, 3.2, True, "lessOrEqual", "entity",
                                          "longitudinal"), "Ego", snap, CTX)
    opening = two(speed=15.0)
    assert not holds(c, "Ego", opening, CTX)
    to_point = TimeToCollisionCondition(None, POINT, 3.0, False, "lessOrEqual", "entity",
                                        "longitudinal")
    assert holds(to_point, "Ego", snapshot(entity("Ego", speed=10.0)), resolver(30.0, 0.0))


def test_reach_position() -> None:
    ctx = resolver(3.0, 4.0)
    assert holds(ReachPositionCondition(POINT, 5.0), "Ego", snapshot(entity("Ego")), ctx)
    assert not holds(ReachPositionCondition(POINT, 4.9), "Ego", snapshot(entity("Ego")), ctx)


def test_entity_state_kinds() -> None:
    e = entity("Ego", speed=0.0, odometer=100.0, standing_for=2.0, off_road_for=1.0,
               end_of_road_for=0.5)
    snap = snapshot(e, entity("Car", speed=3.0))
    assert holds(TraveledDistanceCondition(100.0), "Ego", snap, CTX)
    assert not holds(TraveledDistanceCondition(100.1), "Ego", snap, CTX)
    assert holds(SpeedCondition(0.0, "equalTo"), "Ego", snap, CTX)
    assert holds(RelativeSpeedCondition("Car", -3.0, "equalTo"), "Ego", snap, CTX)
    assert holds(RelativeSpeedCondition("Car", 0.0, "lessThan"), "Ego", snap, CTX)
    assert holds(StandStillCondition(2.0), "Ego", snap, CTX)
    assert not holds(StandStillCondition(2.1), "Ego", snap, CTX)
    assert not holds(StandStillCondition(0.0), "Car", snap, CTX)  # moving
    assert holds(OffroadCondition(1.0), "Ego", snap, CTX)
    assert not holds(OffroadCondition(0.0), "Car", snap, CTX)
    assert holds(EndOfRoadCondition(0.5), "Ego", snap, CTX)
    assert not holds(EndOfRoadCondition(0.6), "Ego", snap, CTX)


def test_collision() -> None:
    """The file's boxes meet (not the bodies' contacts): Ego's box (4 m x 2 m, centre 1.5 m
    ahead of its reference point) spans x -0.5 to 3.5, y -1 to 1; Ped's box starts at x 3.5
    (touching), Car's beside it at y 1.1 (0.1 m apart)."""
    snap = snapshot(entity("Ego"), entity("Car", y=2.1), entity("Ped", x=4.0),
                    categories={"Ego": "vehicle", "Car": "vehicle", "Ped": "pedestrian"})
    assert holds(CollisionCondition("Ped", None), "Ego", snap, CTX)
    assert holds(CollisionCondition("Ego", None), "Ped", snap, CTX)
    assert not holds(CollisionCondition("Car", None), "Ego", snap, CTX)
    assert holds(CollisionCondition(None, "pedestrian"), "Ego", snap, CTX)
    assert not holds(CollisionCondition(None, "vehicle"), "Ego", snap, CTX)
    assert holds(CollisionCondition(None, "vehicle"), "Ped", snap, CTX)
    assert not holds(CollisionCondition(None, "vehicle"), "Car", snap, CTX)


def test_by_value_and_by_entity_are_not_mixed() -> None:
    with pytest.raises(TypeError):
        holds(SpeedCondition(1.0, "lessThan"), None, snapshot(entity()), CTX)
    with pytest.raises(TypeError):
        holds(ElementState.RUNNING, None, snapshot(), CTX)  # type: ignore[arg-type]
