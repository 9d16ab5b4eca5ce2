"""The pass through the oncoming lane: clear -> pass; an oncoming car too close, the sight too
short, a solid centre line, a crossing -> no pass, each with its reason."""

from __future__ import annotations

import pytest

from planner.oncoming_pass import (
    Oncoming,
    PassParams,
    Slow,
    centre_line,
    closing_time,
    decide,
    plan_pass,
)
from tests.planner.maps import KPH, LANE_WIDTH
from world.hdmap import Crosswalk, LineMark, LinePaint, MarkKind, RoadMap
from world.map.road import build_road_map
from world.spec import RoadSpec, SegmentSpec

EGO_LENGTH = 4.6  # [m]
SOLID, BROKEN = LineMark(MarkKind.SOLID, 0.12), LineMark(MarkKind.BROKEN, 0.12)


def one_each_way(centre: LineMark | None, limit_kph: float = 30.0, length: float = 1000.0,
                 crossing: float | None = None) -> RoadMap:
    """A straight 1 + 1 road whose centre line is painted `centre` (None: the road's own
    double solid yellow), with a marked crossing at `crossing` [m]."""
    paint = None if centre is None else LinePaint(SOLID, (), centre, (SOLID,))
    seg = SegmentSpec(length=length, curvature=0.0, lanes=1, oncoming_lanes=1,
                      lane_width=LANE_WIDTH, shoulder=1.0, paint=paint)
    features = () if crossing is None else (Crosswalk(s=crossing, width=4.0),)
    return build_road_map(RoadSpec(segments=(seg,), speed_limit=limit_kph * KPH,
                                   features=features))


LONG_SIGHT = PassParams(sight=400.0)
STOPPED = Slow(gap=12.0, speed=0.0, length=4.6)  # a stopped car 12 m ahead


def test_clear_road_passes() -> None:
    road = one_each_way(BROKEN)
    verdict = decide(road, 100.0, 0.0, 30.0 * KPH, STOPPED, (), EGO_LENGTH, LONG_SIGHT)
    assert verdict.ok and verdict.reason == ""


def test_an_oncoming_car_too_close_is_no_pass_with_its_reason() -> None:
    road = one_each_way(BROKEN)
    plan = plan_pass(0.0, 30.0 * KPH, STOPPED, EGO_LENGTH, LONG_SIGHT)
    assert plan is not None
    car = Oncoming(gap=100.0, speed=30.0 * KPH)
    verdict = decide(road, 100.0, 0.0, 30.0 * KPH, STOPPED, (car,), EGO_LENGTH, LONG_SIGHT)
    assert not verdict.ok
    assert verdict.reason == (f"no pass: oncoming car 100 m ahead closes in "
                              f"{100.0 / (60.0 * KPH):.1f} s, pass needs {plan.time:.1f} s")
    far = Oncoming(gap=plan.travel + car.speed * plan.time + LONG_SIGHT.margin + 1.0,
                   speed=car.speed)  # just beyond what it closes in the pass
    assert decide(road, 100.0, 0.0, 30.0 * KPH, STOPPED, (far,), EGO_LENGTH, LONG_SIGHT).ok


def test_sight_too_short_is_no_pass() -> None:
    """The stack's 55 m of sight: what lies beyond may be a car at the limit."""
    road = one_each_way(BROKEN)
    plan = plan_pass(0.0, 30.0 * KPH, STOPPED, EGO_LENGTH, PassParams())
    assert plan is not None
    need = plan.travel + 30.0 * KPH * plan.time + PassParams().margin
    verdict = decide(road, 100.0, 0.0, 30.0 * KPH, STOPPED, (), EGO_LENGTH, PassParams())
    assert not verdict.ok and verdict.reason == f"no pass: sight 55 m < {need:.0f} m needed"


@pytest.mark.parametrize("centre", [None, SOLID])
def test_no_pass_across_a_solid_centre_line(centre: LineMark | None) -> None:
    road = one_each_way(centre)
    assert centre_line(road, 100.0) is MarkKind.SOLID
    verdict = decide(road, 100.0, 0.0, 30.0 * KPH, STOPPED, (), EGO_LENGTH, LONG_SIGHT)
    assert not verdict.ok and verdict.reason.startswith("no pass: solid centre line")


def test_no_pass_near_a_crossing() -> None:
    road = one_each_way(BROKEN, crossing=150.0)
    verdict = decide(road, 100.0, 0.0, 30.0 * KPH, STOPPED, (), EGO_LENGTH, LONG_SIGHT)
    assert verdict == verdict.__class__(False, "no pass: a marked crossing within the pass")


def test_a_vehicle_nearly_as_fast_is_not_passed() -> None:
    road = one_each_way(BROKEN)
    slow = Slow(gap=20.0, speed=29.0 * KPH, length=4.6)
    verdict = decide(road, 100.0, 8.0, 30.0 * KPH, slow, (), EGO_LENGTH, LONG_SIGHT)
    assert not verdict.ok and "not slower than the pass speed" in verdict.reason


@pytest.mark.parametrize(("distance", "v0", "v_max", "a", "expected"), [
    (10.0, 2.0, 2.0, 1.0, 5.0),  # at a constant relative speed
    (4.0, 0.0, 4.0, 2.0, 2.0),  # speeding up all the way: 0.5 * 2 * 2^2 = 4
    (8.0, 0.0, 2.0, 2.0, 4.5),  # 1 s (1 m) up to 2 m/s, then 7 m at 2 m/s
])
def test_closing_time(distance: float, v0: float, v_max: float, a: float,
                      expected: float) -> None:
    assert closing_time(distance, v0, v_max, a) == pytest.approx(expected)


def test_the_motion_layer_says_once_why_it_stays_behind() -> None:
    """overtake on, a 1 + 1 road, a stopped car ahead: the car keeps its lane, and the
    reason (the sight too short) is logged once, not every tick."""
    from perception.messages import EgoState, ObjectClass, Track
    from planner.fsm.acc import AccParams
    from planner.fsm.motion import Motion
    from planner.motion_layer import MotionLayer, MotionLayerParams
    from tests.vehicle import VEHICLE

    road = one_each_way(BROKEN)
    layer = MotionLayer(road, 0, AccParams(), VEHICLE, MotionLayerParams(overtake=True))
    logged = []
    for k in range(30):
        t = 0.1 * k
        ego = EgoState(t, 100.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.1)
        car = Track(id=7, t=t, x=125.0, y=0.0, vx=0.0, vy=0.0, rel_x=25.0, rel_y=0.0,
                    rel_vx=-5.0, rel_vy=0.0, length=4.6, width=1.8, height=1.5, yaw=0.0,
                    cls=ObjectClass.CAR, hits=20, misses=0, position_sigma=0.1)
        manoeuvre, changes = layer.update(ego, 30.0 * KPH, (car,))
        assert manoeuvre.motion is Motion.LANE_KEEP and manoeuvre.lane == 0
        logged += [c.reason for c in changes]
    assert len(logged) == 1 and logged[0].startswith("no pass: sight 55 m < ")
