"""The pass through the oncoming lane: clear -> pass; an oncoming car too close, the sight too
short for the half-sight rule, a solid centre line, a crossing -> no pass, each with its
reason; the speed cap in the oncoming lane."""

from __future__ import annotations

import math
from collections.abc import Callable

import pytest

from perception.messages import EgoState, ObjectClass, Track
from planner.fsm.acc import AccParams
from planner.fsm.motion import Motion
from planner.motion_layer import Manoeuvre, MotionLayer, MotionLayerParams
from planner.oncoming_pass import (
    Oncoming,
    PassParams,
    Slow,
    centre_line,
    closing_time,
    decide,
    plan_pass,
    sight_needed,
    speed_cap,
    stopping_distance,
)
from tests.planner.maps import KPH, LANE_WIDTH
from tests.vehicle import VEHICLE
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


def test_the_stacks_sight_allows_a_pass_on_a_30_kph_road() -> None:
    """Half-sight rule: at 30 km/h each stops within 8.3 + 5.8 = 14.1 m; 28 m < 55 m."""
    road = one_each_way(BROKEN, limit_kph=30.0)
    assert sight_needed(30.0 * KPH, 30.0 * KPH, PassParams()) == pytest.approx(28.3, abs=0.1)
    verdict = decide(road, 100.0, 0.0, 30.0 * KPH, STOPPED, (), EGO_LENGTH, PassParams())
    assert verdict.ok and verdict.reason == ""


def test_sight_too_short_at_50_kph_is_no_pass_with_its_reason() -> None:
    """At 50 km/h each needs 13.9 + 16.1 = 30 m to stop: 60 m > the stack's 55 m."""
    road = one_each_way(BROKEN, limit_kph=50.0)
    verdict = decide(road, 100.0, 0.0, 50.0 * KPH, STOPPED, (), EGO_LENGTH, PassParams())
    assert verdict == verdict.__class__(False, "no pass: sight 55 m < 60 m needed")
    longer = PassParams(sight=61.0)  # the same pass with 61 m of sight is allowed
    assert decide(road, 100.0, 0.0, 50.0 * KPH, STOPPED, (), EGO_LENGTH, longer).ok


def test_stopping_distance() -> None:
    p = PassParams()
    assert stopping_distance(12.0, p) == pytest.approx(12.0 + 144.0 / 12.0)
    assert stopping_distance(-1.0, p) == 0.0


@pytest.mark.parametrize("limit_kph", [30.0, 40.0, 50.0, 70.0])
def test_the_speed_cap_in_the_oncoming_lane_keeps_the_half_sight_rule(
        limit_kph: float) -> None:
    """The cap is the highest speed at which the car and an oncoming vehicle at the limit
    both stop within the sight: at it the two stopping distances fill the sight exactly."""
    p = PassParams()
    limit = limit_kph * KPH
    cap = speed_cap(limit, p)
    if stopping_distance(limit, p) >= p.sight:
        assert cap == 0.0
        return
    assert sight_needed(cap, limit, p) == pytest.approx(p.sight)
    assert sight_needed(cap + 0.1, limit, p) > p.sight


def test_the_speed_cap_binds_only_above_the_speed_a_pass_is_allowed_at() -> None:
    """A 30 km/h road: the car may go up to 61 km/h before the rule binds; a 50 km/h road:
    44 km/h, below its limit (so no pass starts there at the limit)."""
    p = PassParams()
    assert speed_cap(30.0 * KPH, p) == pytest.approx(16.95, abs=0.01)
    assert speed_cap(50.0 * KPH, p) == pytest.approx(12.34, abs=0.01)
    assert speed_cap(80.0 * KPH, p) == 0.0  # 22.2 + 41.2 m > 55 m: none


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
    """overtake on, a 1 + 1 road at 50 km/h, a stopped car ahead: the car keeps its lane,
    and the reason (the sight too short) is logged once, not every tick."""
    road = one_each_way(BROKEN, limit_kph=50.0)
    layer = MotionLayer(road, 0, AccParams(), VEHICLE, MotionLayerParams(overtake=True))
    logged = []
    for k in range(30):
        t = 0.1 * k
        ego = EgoState(t, 100.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.1)
        car = Track(id=7, t=t, x=125.0, y=0.0, vx=0.0, vy=0.0, rel_x=25.0, rel_y=0.0,
                    rel_vx=-5.0, rel_vy=0.0, length=4.6, width=1.8, height=1.5, yaw=0.0,
                    cls=ObjectClass.CAR, hits=20, misses=0, position_sigma=0.1)
        manoeuvre, changes = layer.update(ego, 50.0 * KPH, (car,))
        assert manoeuvre.motion is Motion.LANE_KEEP and manoeuvre.lane == 0
        logged += [c.reason for c in changes]
    assert logged == ["no pass: sight 55 m < 60 m needed"]


def _track(track_id: int, t: float, x: float, y: float, vx: float) -> Track:
    return Track(id=track_id, t=t, x=x, y=y, vx=vx, vy=0.0, rel_x=0.0, rel_y=0.0, rel_vx=0.0,
                 rel_vy=0.0, length=4.6, width=1.8, height=1.5, yaw=0.0,
                 cls=ObjectClass.CAR, hits=20, misses=0, position_sigma=0.1)


def _drive(road: RoadMap, oncoming: Callable[[float], tuple[Track, ...]], v: float,
           steps: int) -> tuple[list[tuple[float, Manoeuvre]], list[str]]:
    """A car at `v` [m/s] from x = 100 m on lane 0's centre behind a car stopped at
    x = 130 m, following the motion layer's lane and path exactly (kinematic, 10 Hz), with
    the tracks `oncoming(t)` besides: every tick's (x, manoeuvre) and the logged reasons."""
    layer = MotionLayer(road, 0, AccParams(), VEHICLE, MotionLayerParams(overtake=True))
    x, y, out, reasons = 100.0, 0.0, [], []
    for k in range(steps):
        t = 0.1 * k
        tracks = (_track(7, t, 130.0, 0.0, 0.0), *oncoming(t))
        m, changes = layer.update(EgoState(t, x, y, 0.0, v, 0.0, 0.0, 0.1), 30.0 * KPH, tracks)
        reasons += [c.reason for c in changes if c.source == c.target]
        out.append((x, m))
        x += v * 0.1
        lane = road.lane(m.lane)
        y = float(lane.offset_at(x)) + (0.0 if m.path is None else float(m.path.offset_at(x)))
    return out, reasons


def test_the_pass_goes_through_the_oncoming_lane_and_back_at_30_kph() -> None:
    """No oncoming traffic on a 30 km/h road: the car pulls into lane -1, draws past the
    stopped car with its speed capped by the half-sight rule, and returns to lane 0 once
    the car is `return_gap` behind."""
    road = one_each_way(BROKEN)
    run, reasons = _drive(road, lambda t: (), 5.0, 200)
    motions = [m.motion for _, m in run]
    lanes = [m.lane for _, m in run]
    assert reasons == []
    start = motions.index(Motion.LANE_CHANGE_LEFT)
    assert lanes[start] == -1 and run[start][0] < 130.0 - 2.3 - 4.0  # from behind it
    back = start + motions[start:].index(Motion.LANE_CHANGE_RIGHT)
    assert lanes[back] == 0 and run[back][1].origin == -1
    # back once the stopped car (its front to the car's rear bumper) is return_gap (8 m)
    # + back_margin (2 m) behind, within a tick (0.5 m) and the track's box (0.5 m)
    front_of_stopped = 130.0 + 2.3
    ego_rear = run[back][0] - VEHICLE.rear_overhang
    assert 10.0 <= ego_rear - front_of_stopped < 10.0 + 5.0 * 0.1 + 0.5
    assert lanes[-1] == 0 and motions[-1] is Motion.LANE_KEEP
    caps = {m.speed_cap for _, m in run if min(m.lane, m.origin) < 0}
    assert caps == {speed_cap(30.0 * KPH, PassParams())}
    assert all(m.speed_cap == math.inf for _, m in run[:start])


def test_a_tracked_oncoming_car_keeps_the_car_behind_with_the_reason() -> None:
    """An oncoming car at 30 km/h, tracked 50 m ahead of the car's front and closing: the
    car stays in lane 0 (where the same run without it pulls out, above), and says why."""
    road = one_each_way(BROKEN)
    run, reasons = _drive(
        road, lambda t: (_track(9, t, 157.0 - 30.0 * KPH * t, LANE_WIDTH, -30.0 * KPH),),
        5.0, 40)
    assert all(m.lane == 0 and m.motion is Motion.LANE_KEEP for _, m in run)
    assert len(reasons) == 1 and reasons[0].startswith("no pass: oncoming car ")
    alone, _ = _drive(road, lambda t: (), 5.0, 40)
    assert any(m.lane == -1 for _, m in alone)


def test_an_oncoming_car_seen_before_alongside_aborts_the_pass() -> None:
    """The pass starts with the lane clear; an oncoming car tracked 50 m ahead while the
    car is still behind the stopped one: back into lane 0 (the lane-change abort)."""
    road = one_each_way(BROKEN)
    seen: list[float] = []

    def oncoming(t: float) -> tuple[Track, ...]:
        return (_track(9, t, 200.0, LANE_WIDTH, -30.0 * KPH),) if seen and t >= seen[0] \
            else ()

    layer_run, _ = _drive(road, lambda t: (), 3.0, 60)
    start = next(k for k, (_, m) in enumerate(layer_run) if m.lane == -1)
    seen.append(0.1 * start + 0.3)
    run, _ = _drive(road, oncoming, 3.0, 60)
    motions = [(m.motion, m.lane) for _, m in run]
    after = motions[start + 3:]
    assert (Motion.LANE_KEEP, 0) in after and after[-1] == (Motion.LANE_KEEP, 0)
    assert all(x < 130.0 for x, _ in run[start:start + 5])  # still behind it
