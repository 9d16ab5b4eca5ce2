"""Judging the acceleration, angle, relative angle and relative clearance conditions on
hand-made snapshots (tables)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from avsim.run.storyboard.conditions import ConditionContext, holds
from avsim.run.storyboard.snapshot import EntityState
from avsim.run.storyboard.truth import TruthTracker
from avsim.scenario.openscenario.conditions import (
    AccelerationCondition,
    AngleCondition,
    ConditionKind,
    RelativeAngleCondition,
    RelativeClearanceCondition,
)
from tests.avsim.run.storyboard.helpers import entity, snapshot

TWO_BY_ONE = ConditionContext({}, {}, lanes=lambda s: (2, 1))  # two lanes our way, one oncoming


def judged(kind: ConditionKind, *others: EntityState, ego: EntityState | None = None) -> bool:
    me = ego or entity("Ego")
    return holds(kind, "Ego", snapshot(me, *others), TWO_BY_ONE)


BRAKING = entity("Ego", speed=10.0, acceleration=-4.0, yaw_rate=0.3)  # lateral 3 m/s² left


@pytest.mark.parametrize(("kind", "expected"), [
    (AccelerationCondition(-3.0, "lessThan", "longitudinal"), True),
    (AccelerationCondition(2.9, "greaterThan", "lateral"), True),
    (AccelerationCondition(3.1, "greaterThan", "lateral"), False),
    (AccelerationCondition(0.0, "equalTo", "vertical"), True),
    (AccelerationCondition(-5.0, "equalTo", None), True),  # |(-4, 3)| signed as -4
    (AccelerationCondition(4.0, "greaterThan", None), False),
])
def test_acceleration(kind: AccelerationCondition, expected: bool) -> None:
    assert judged(kind, ego=BRAKING) is expected


TURNED = entity("Ego", heading=0.6, route_heading=0.5, lane=0)
ONCOMING = entity("Ego", heading=0.5 + math.pi, route_heading=0.5, lane=-1)


@pytest.mark.parametrize(("ego", "kind", "expected"), [
    (TURNED, AngleCondition("heading", 0.6, 0.01, "world"), True),
    (TURNED, AngleCondition("heading", 0.1, 0.01, "road"), True),
    (TURNED, AngleCondition("heading", 0.1, 0.01, "lane"), True),
    (TURNED, AngleCondition("heading", 0.0, 0.01, "entity"), True),
    (TURNED, AngleCondition("heading", 0.5, 0.05, "world"), False),
    (TURNED, AngleCondition("heading", 0.6 + 2 * math.pi, 0.01, "world"), True),  # wrapped
    (ONCOMING, AngleCondition("heading", math.pi, 0.01, "road"), True),
    (ONCOMING, AngleCondition("heading", 0.0, 0.01, "lane"), True),  # its driving direction
    (TURNED, AngleCondition("pitch", 0.0, 0.0, "world"), True),  # flat: pitch and roll 0
    (TURNED, AngleCondition("roll", 0.1, 0.05, "world"), False),
])
def test_angle(ego: EntityState, kind: AngleCondition, expected: bool) -> None:
    assert judged(kind, ego=ego) is expected


@pytest.mark.parametrize(("kind", "expected"), [
    (RelativeAngleCondition("Car", "heading", -0.4, 0.01, "entity"), True),
    (RelativeAngleCondition("Car", "heading", -0.4, 0.01, "world"), True),
    (RelativeAngleCondition("Car", "heading", 0.4, 0.01, "world"), False),
    (RelativeAngleCondition("Car", "heading", -0.2, 0.01, "road"), True),  # 0.1 - 0.3
])
def test_relative_angle(kind: RelativeAngleCondition, expected: bool) -> None:
    car = entity("Car", heading=1.0, route_heading=0.7)
    assert judged(kind, car, ego=TURNED) is expected


def clearance(forward: float = 50.0, backward: float = 10.0, freespace: bool = False,
              opposite: bool = False, ranges: tuple[tuple[int | None, int | None], ...] = (),
              entities: tuple[str, ...] = ()) -> RelativeClearanceCondition:
    return RelativeClearanceCondition(entities, forward, backward, freespace, opposite, ranges)


LEFT = ((1, 1),)
EGO = entity("Ego", x=100.0, y=0.0, lane=0)


@pytest.mark.parametrize(("kind", "others", "expected"), [
    (clearance(ranges=LEFT), (), True),
    (clearance(ranges=LEFT), (entity("Car", x=130.0, y=3.5, lane=1),), False),
    (clearance(ranges=LEFT), (entity("Car", x=160.0, y=3.5, lane=1),), True),  # too far
    (clearance(ranges=LEFT), (entity("Car", x=91.0, y=3.5, lane=1),), False),
    (clearance(ranges=LEFT), (entity("Car", x=89.0, y=3.5, lane=1),), True),  # behind
    (clearance(ranges=LEFT, freespace=True), (entity("Car", x=86.0, y=3.5, lane=1),), False),
    (clearance(ranges=LEFT), (entity("Car", x=120.0, y=0.0, lane=0),), True),  # own lane
    (clearance(), (entity("Car", x=120.0, y=0.0, lane=0),), False),  # every lane
    (clearance(ranges=((2, 2),)), (), False),  # no lane there but the oncoming one
    (clearance(ranges=((2, 2),), opposite=True), (), True),
    (clearance(ranges=((2, 2),), opposite=True), (entity("Car", x=120.0, y=7.0, lane=-1),),
     False),
    (clearance(ranges=((2, 2),)), (entity("Car", x=120.0, y=7.0, lane=-1),), False),
    (clearance(ranges=((-1, -1),)), (), False),  # nothing right of lane 0
    (clearance(ranges=LEFT, entities=("Bike",)), (entity("Car", x=130.0, y=3.5, lane=1),
                                                   entity("Bike", x=300.0, lane=1)), True),
    (clearance(ranges=LEFT), (entity("Car", x=130.0, y=3.5, lane=None),), True),  # off lanes
])
def test_clearance(kind: RelativeClearanceCondition, others: tuple[EntityState, ...],
                   expected: bool) -> None:
    assert judged(kind, *others, ego=EGO) is expected


def test_clearance_from_an_oncoming_lane_looks_its_own_way() -> None:
    me = entity("Ego", x=100.0, y=7.0, lane=-1, heading=math.pi)
    car = entity("Car", x=105.0, y=3.5, lane=1)  # ahead along the route: 5 m behind it,
    #   in the lane on its left (across the centre line)
    kind = clearance(forward=50.0, backward=2.0, ranges=((1, 1),), opposite=True)
    assert judged(kind, car, ego=me) is True
    kind = clearance(forward=50.0, backward=10.0, ranges=((1, 1),), opposite=True)
    assert judged(kind, car, ego=me) is False
    kind = clearance(forward=50.0, backward=10.0, ranges=((1, 1),), opposite=False)
    assert judged(kind, car, ego=me) is False  # a lane of its direction on its left: none
    assert judged(clearance(ranges=((-1, -1),), opposite=True), ego=me) is False  # right: none


def test_clearance_off_the_lanes_is_false() -> None:
    assert judged(clearance(), ego=entity("Ego", lane=None)) is False


def test_the_truth_differences_speed_and_heading_between_checks() -> None:
    tracker = TruthTracker.__new__(TruthTracker)  # the rates need no world
    tracker._speed, tracker._yaw = np.zeros(2), np.zeros(2)
    acc, turn = tracker._rates(0.0, np.array([5.0, 1.0]), np.array([3.1, 0.0]))
    assert acc.tolist() == [0.0, 0.0] and turn.tolist() == [0.0, 0.0]  # the first: zeros
    acc, turn = tracker._rates(0.5, np.array([4.0, 2.0]), np.array([-3.1, 0.1]))
    assert acc == pytest.approx([-2.0, 2.0])
    assert turn == pytest.approx([(2 * math.pi - 6.2) / 0.5, 0.2])  # across the half turn
