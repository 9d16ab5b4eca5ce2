"""Conditions on an entity out of the world (deleted, or not yet added: the snapshot's
`inactive`), judged as esmini judges an inactive entity: skipped as a triggering entity
(rule "all" counts only those in the world), absent as a reference, a collision partner or a
car in a clearance's lanes. The held state of an inactive entity is made to hold each
condition here, so every assertion fails if that state were read."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from avsim.run.storyboard.conditions import ConditionContext, judge
from avsim.run.storyboard.snapshot import Snapshot
from avsim.run.storyboard.truth import TruthTracker
from avsim.scenario.openscenario.conditions import (
    AccelerationCondition,
    CollisionCondition,
    ConditionKind,
    EndOfRoadCondition,
    OffroadCondition,
    RelativeClearanceCondition,
    RelativeDistanceCondition,
    RelativeSpeedCondition,
    SpeedCondition,
    StandStillCondition,
    TimeHeadwayCondition,
    TimeToCollisionCondition,
    TraveledDistanceCondition,
)
from tests.avsim.run.storyboard.helpers import condition, context, entity, snapshot

CTX = context()
EGO = entity("Ego", speed=10.0)
# Gone's held state: standing, off the road, beyond its ends, far travelled, 10 m ahead of
# the ego (its box meeting nothing but Near's)
GONE = entity("Gone", x=10.0, speed=0.0, standing_for=5.0, off_road_for=5.0,
              end_of_road_for=5.0, odometer=500.0)
NEAR = entity("Near", x=13.0, speed=0.0)  # its box touches Gone's


def with_gone(*entities: object, gone: frozenset[str] = frozenset({"Gone"})) -> Snapshot:
    snap = snapshot(EGO, GONE, NEAR, *entities)  # type: ignore[arg-type]
    return dataclasses.replace(snap, inactive=gone)


@pytest.mark.parametrize("kind", [
    StandStillCondition(1.0),
    EndOfRoadCondition(1.0),
    OffroadCondition(1.0),
    TraveledDistanceCondition(100.0),
    SpeedCondition(1.0, "lessThan"),
    AccelerationCondition(1.0, "lessThan", "longitudinal"),
    CollisionCondition("Near", None),
    CollisionCondition(None, "vehicle"),
    RelativeDistanceCondition("Ego", "longitudinal", 20.0, False, "lessThan", "entity"),
])
def test_an_inactive_triggering_entity_never_holds(kind: ConditionKind) -> None:
    active = dataclasses.replace(with_gone(), inactive=frozenset())
    assert judge(condition(kind, entities=("Gone",)), active, CTX) == (True, ("Gone",))
    for rule in ("any", "all"):
        assert judge(condition(kind, entities=("Gone",), rule=rule), with_gone(), CTX) == (
            False, ())


def test_rule_all_counts_the_entities_in_the_world_only() -> None:
    still = StandStillCondition(1.0)
    near = dataclasses.replace(NEAR, standing_for=2.0)
    snap = dataclasses.replace(snapshot(EGO, GONE, near), inactive=frozenset({"Gone"}))
    assert judge(condition(still, entities=("Gone", "Near"), rule="all"), snap, CTX) == (
        True, ("Near",))
    moving = dataclasses.replace(snap, inactive=frozenset({"Near"}))  # Gone back, Near out
    assert judge(condition(still, entities=("Gone", "Near"), rule="all"), moving, CTX) == (
        True, ("Gone",))
    none_left = dataclasses.replace(snap, inactive=frozenset({"Gone", "Near"}))
    assert judge(condition(still, entities=("Gone", "Near"), rule="all"), none_left, CTX) == (
        False, ())
    slow_ego = SpeedCondition(20.0, "lessThan")  # Ego holds, Gone would too, Near does
    assert judge(condition(slow_ego, entities=("Ego", "Gone", "Near"), rule="all"), snap,
                 CTX) == (True, ("Ego", "Near"))


@pytest.mark.parametrize("kind", [
    RelativeDistanceCondition("Gone", "longitudinal", 20.0, False, "lessThan", "entity"),
    RelativeSpeedCondition("Gone", 5.0, "greaterThan"),
    TimeHeadwayCondition("Gone", 5.0, False, "lessThan", "entity", "longitudinal"),
    TimeToCollisionCondition("Gone", None, 5.0, False, "lessThan", "entity", "longitudinal"),
    CollisionCondition("Gone", None),
])
def test_an_inactive_reference_entity_is_absent(kind: ConditionKind) -> None:
    trigger = "Near" if isinstance(kind, CollisionCondition) else "Ego"
    c = condition(kind, entities=(trigger,))
    assert judge(c, dataclasses.replace(with_gone(), inactive=frozenset()), CTX)[0]
    assert judge(c, with_gone(), CTX) == (False, ())


def test_a_collision_by_type_and_a_clearance_do_not_see_an_inactive_entity() -> None:
    by_type = condition(CollisionCondition(None, "vehicle"), entities=("Near",))
    assert judge(by_type, dataclasses.replace(with_gone(), inactive=frozenset()), CTX)[0]
    assert not judge(by_type, with_gone(), CTX)[0]
    lanes = ConditionContext({}, {}, lanes=lambda s: (2, 1))
    ego = entity("Ego", lane=0)
    gone = entity("Gone", x=20.0, lane=0)
    clear = condition(RelativeClearanceCondition((), 50.0, 10.0, False, False, ()),
                      entities=("Ego",))
    snap = snapshot(ego, gone)
    assert not judge(clear, snap, lanes)[0]
    assert judge(clear, dataclasses.replace(snap, inactive=frozenset({"Gone"})), lanes)[0]


def test_an_entity_out_of_the_world_travels_nothing() -> None:
    """The truth's odometer does not integrate the held speed of an actor out of the world
    (esmini does not step an inactive entity), which counts as standing."""
    tracker = TruthTracker.__new__(TruthTracker)  # the running figures need a road only
    tracker.road = type("Road", (), {
        "paved_edges": lambda self, s: (s * 0 - 5, s * 0 + 5), "length": 1000.0})()
    tracker.odometer, tracker.standing = np.zeros(3), np.zeros(3)
    tracker.off_road, tracker.beyond = np.zeros(3), np.zeros(3)
    present = np.array([True, True, False])
    tracker._integrate(0.5, np.full(3, 10.0), np.full(3, 10.0), np.zeros(3), present)
    assert tracker.odometer.tolist() == [5.0, 5.0, 0.0]
    assert tracker.standing.tolist() == [0.0, 0.0, 0.5]
