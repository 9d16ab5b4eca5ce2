"""The DECS events from the map and perception, and the ACC layer's event laws."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from perception.messages import ObjectClass, Track
from planner.acc_control import AccControlParams, bump, stop, stop_speed
from planner.acc_layer import AccLayer
from planner.events import EventMonitor, EventParams, Events
from planner.fsm.acc import AccEvent, AccMode
from planner.messages import SpeedSource
from planner.speed import PlannedSpeed, SpeedRef
from planner.speed_planning import SpeedPlanner, SpeedPlanningParams
from tests.roads import KPH, W, make_map, seg
from tests.vehicle import VEHICLE
from world.hdmap import Crosswalk, SpeedBump, StopSign, Zone

FLAT, OFF_RAMP, PEDESTRIAN = AccEvent.FLAT, AccEvent.OFF_RAMP, AccEvent.PEDESTRIAN
SPEED_BUMP, STOP_SIGN = AccEvent.SPEED_BUMP, AccEvent.STOP_SIGN

P = EventParams()
FEATURES = (StopSign(200.0), SpeedBump(300.0, 0.1, 0.9, 5 * KPH), Crosswalk(400.0, 4.0))
ROAD = make_map(seg(500.0), replace(seg(100.0), zone=Zone.RAMP), features=FEATURES)


def walker(x: float, y: float, vy: float = 0.0) -> Track:
    return Track(id=7, t=0.0, x=x, y=y, vx=0.0, vy=vy, rel_x=0.0, rel_y=0.0, rel_vx=0.0,
                 rel_vy=0.0, length=0.5, width=0.6, height=1.75, yaw=0.0,
                 cls=ObjectClass.PEDESTRIAN, hits=9, misses=0, position_sigma=0.1)


def at(m: EventMonitor, station: float, v: float = 8.0, t: float = 0.0,
       tracks: tuple[Track, ...] = ()) -> Events:
    return m.update(t, station, v, 0.0, W, tracks)


def test_a_stop_sign_counts_once_perception_confirmed_it_until_the_stop_is_done() -> None:
    m = EventMonitor(ROAD, VEHICLE, P)
    assert not at(m, 150.0).holds(STOP_SIGN)  # not seen yet
    m.confirm_sign(200.0)
    e = at(m, 150.0)
    assert e.holds(STOP_SIGN) and e.stop_distance == pytest.approx(200.0 - 152.4 - 0.5)
    assert not at(m, 100.0).holds(STOP_SIGN)  # 97.6 m before the line: beyond the approach at 8 m/s
    standing = 200.0 - 2.4 - 1.5  # front bumper 1.5 m before the line
    assert at(m, standing, v=0.0, t=10.0).holds(STOP_SIGN)
    assert at(m, standing, v=0.0, t=11.4).holds(STOP_SIGN)
    assert not at(m, standing, v=0.0, t=11.6).holds(STOP_SIGN)  # stood 1.5 s: done, go
    assert not at(m, standing + 2.0, v=3.0, t=12.0).holds(STOP_SIGN)


def test_a_bump_from_its_approach_until_the_rear_axle_is_past() -> None:
    m = EventMonitor(ROAD, VEHICLE, P)
    e = at(m, 270.0, v=10.0)
    near = 300.0 - 0.45
    assert e.holds(SPEED_BUMP) and e.bump_speed == pytest.approx(4.5 * KPH)
    assert e.bump_distance == pytest.approx(near - 1.0 - (270.0 + 1.35))
    assert at(m, 300.0 + 0.45 + 1.0 + 1.35 - 0.01, v=1.4).holds(SPEED_BUMP)
    assert not at(m, 300.0 + 0.45 + 1.0 + 1.35 + 0.01, v=1.4).holds(SPEED_BUMP)


def test_a_bump_once_approached_holds_while_braking_for_it_shrinks_the_approach() -> None:
    """Entered 62.2 m before the bump at 10 m/s (approach 63.3 m); 0.5 m on at 9 m/s the
    approach is 57 m, short of the bump, but the event holds until the bump is passed (it
    ended and began again for a tick: a SPEED_BUMP mode held 0.025 s in city_stop_40)."""
    m = EventMonitor(ROAD, VEHICLE, P)
    assert at(m, 236.0, v=10.0).holds(SPEED_BUMP)
    assert at(m, 236.5, v=9.0).holds(SPEED_BUMP)
    assert not at(EventMonitor(ROAD, VEHICLE, P), 236.5, v=9.0).holds(SPEED_BUMP)  # never
    #   entered: not yet
    assert not at(m, 300.0 + 0.45 + 1.0 + 1.35 + 0.01, v=1.4).holds(SPEED_BUMP)  # passed
    assert not at(m, 236.5, v=9.0).holds(SPEED_BUMP)  # forgotten once passed


def test_a_pedestrian_on_or_walking_into_the_crossing_in_the_lane() -> None:
    m = EventMonitor(ROAD, VEHICLE, P)
    on = at(m, 370.0, tracks=(walker(402.0, 0.5),))
    assert on.holds(PEDESTRIAN) and on.stop_distance == pytest.approx(400.0 - 372.4 - 1.0)
    assert not at(m, 370.0, tracks=(walker(402.0, -6.0),)).holds(PEDESTRIAN)  # on the pavement
    into = at(m, 370.0, tracks=(walker(402.0, -4.0, vy=1.4),))  # 2.8 m closer in 2 s
    assert into.holds(PEDESTRIAN)
    off = at(m, 370.0, tracks=(walker(402.0, 4.0 + W, vy=1.4),))  # walking off
    assert not off.holds(PEDESTRIAN)
    assert not at(m, 370.0, tracks=(walker(420.0, 0.0),)).holds(PEDESTRIAN)  # not at the crossing
    assert not at(m, 398.0, tracks=(walker(402.0, 0.5),)).holds(PEDESTRIAN)  # already on it: go on


def test_the_ramp_zone_is_the_off_ramp() -> None:
    m = EventMonitor(ROAD, VEHICLE, P)
    assert not at(m, 490.0).holds(OFF_RAMP) and at(m, 510.0).holds(OFF_RAMP)
    # from the front bumper on, where the ramp's limit applies (not from the car's centre)
    front = 500.0 - VEHICLE.front_overhang
    assert not at(m, front - 0.01).holds(OFF_RAMP) and at(m, front + 0.01).holds(OFF_RAMP)


@pytest.mark.parametrize("lane", [0, 1])
def test_the_off_ramp_holds_exactly_while_the_ramps_limit_is_in_force(lane: int) -> None:
    """The event and the ramp's lower limit start and end on the same tick (issue K: no
    SPEED_LIMIT between CRUISE and OFF_RAMP), also after a curve, where the speed plan's
    front bumper is the lane's length ahead of the centre, not the reference line's."""
    road = make_map(seg(100.0, 60.0), seg(50.0, speed_kph=25.0, zone=Zone.RAMP),
                    seg(100.0, -60.0, speed_kph=40.0, zone=Zone.CITY))
    plan = SpeedPlanner(road, road.lane(lane), SpeedPlanningParams(), VEHICLE)
    m = EventMonitor(road, VEHICLE, P)
    ramp = 25.0 * KPH
    for s in np.arange(90.0, 160.0, 0.01):
        target = plan.target(float(s), set_speed=20.0, max_speed=30.0)
        e = m.update(0.0, float(s), 5.0, 0.0, W, limit_station=plan.front_station(float(s)))
        assert e.holds(OFF_RAMP) is (target.limit_at_front == ramp), s


C = AccControlParams()
PLAN = PlannedSpeed(SpeedRef(12.0, 0.0), SpeedSource.LIMIT)  # the map's plan


@pytest.mark.parametrize(("events", "mode", "v", "speed"), [
    # met faster than their laws (at 10 m/s): the planned deceleration from the speed
    (Events(active=frozenset({STOP_SIGN}), stop_distance=20.0), AccMode.STOP_SIGN, 10.0,
     stop(20.0, 10.0, 12.0, 0.025, C).speed),
    (Events(active=frozenset({PEDESTRIAN}), stop_distance=8.0), AccMode.PEDESTRIAN, 10.0,
     stop(8.0, 10.0, 12.0, 0.025, C).speed),
    (Events(active=frozenset({SPEED_BUMP}), bump_distance=15.0, bump_speed=1.3),
     AccMode.SPEED_BUMP, 10.0, bump(15.0, 1.3, 10.0, 12.0, 0.025, C).speed),
    # on its curve: the law itself
    (Events(active=frozenset({STOP_SIGN}), stop_distance=30.0), AccMode.STOP_SIGN,
     stop_speed(30.0, 12.0, C), stop_speed(30.0, 12.0, C)),
    (Events(active=frozenset({OFF_RAMP})), AccMode.OFF_RAMP, 10.0, 12.0),
])
def test_the_event_modes_and_their_laws(events: Events, mode: AccMode, v: float,
                                        speed: float) -> None:
    layer = AccLayer()
    layer.update(0.0, 0.025, v, 15.0, 20.0, PLAN, None)  # on: cruise
    out, changes = layer.update(0.025, 0.025, v, 15.0, 20.0, PLAN, None, events=events)
    assert layer.mode is mode and changes[0].target == mode.value
    assert out.speed.ref.speed == pytest.approx(speed)
    # the event's law set the speed where it is below the plan's (the ramp: the plan's)
    expected = SpeedSource.EVENT if speed < PLAN.ref.speed else PLAN.source
    assert out.speed.source is expected


def test_flat_eases_to_a_crawl_then_stops_once_pulled_over() -> None:
    layer = AccLayer()
    layer.update(0.0, 0.025, 10.0, 15.0, 20.0, PLAN, None)
    v, t = 10.0, 0.0
    for k in range(800):
        t += 0.025
        out, _ = layer.update(t, 0.025, v, 15.0, 20.0, PLAN, None,
                              events=Events(active=frozenset({FLAT}), pulled_over=k >= 400))
        ref = out.speed.ref
        assert out.speed.source is SpeedSource.EVENT
        assert ref.speed <= v and ref.accel >= -C.a_flat
        v = ref.speed
        if k == 399:  # 10 s on: crawling while it pulls over
            assert v == pytest.approx(C.v_pull_over)
    assert layer.mode is AccMode.FLAT and v == 0.0 and math.isfinite(t)


def test_a_camera_stop_sign_confirms_the_map_line_near_it() -> None:
    from perception.messages import EgoState, SignDetection

    m = EventMonitor(ROAD, VEHICLE, P)
    pose = EgoState(t=5.0, x=160.0, y=0.0, heading=0.0, speed=8.0, yaw_rate=0.0,
                    steering_angle=0.0, position_sigma=0.05)
    left = SignDetection(5.0, "stop", 41.0, 4.0, 2.0, 41.2, (0, 0, 1, 1), 0.9)
    m.see_signs([left], pose)  # left of the route: not this line's sign
    far = SignDetection(5.0, "stop", 20.0, -4.0, 2.0, 20.4, (0, 0, 1, 1), 0.9)
    m.see_signs([far], pose)  # 20 m short of the line
    assert not m.confirmed
    seen = SignDetection(5.0, "stop", 38.0, -4.3, 2.0, 38.2, (0, 0, 1, 1), 0.9)
    m.see_signs([seen], pose)
    assert m.confirmed == {200.0}


def test_a_pedestrian_waits_at_a_crossing_ahead_from_the_kerb_or_the_far_side() -> None:
    """`EventMonitor.waiting`: the crosswalk at 400 m (width 4 m) counts while a walker is
    at it, on either side within `waiting_reach` of the lane's edges, before it has
    started to walk (no event yet) and until the front bumper reaches the crosswalk."""
    m = EventMonitor(ROAD, VEHICLE, P)
    edge = 0.5 * W + P.waiting_reach  # [m] from the lane's centre
    kerb = walker(401.5, -5.0)  # standing on the right-hand pavement, 3.25 m off the lane
    assert not at(m, 370.0, tracks=(kerb,)).holds(PEDESTRIAN)  # not walking: no event
    assert m.waiting(370.0, 0.0, W, (kerb,)) == frozenset({400.0})
    assert m.waiting(370.0, 0.0, W, (walker(401.5, 6.5),)) == frozenset({400.0})  # far side
    assert m.waiting(370.0, 0.0, W, (walker(401.5, edge - 0.01),)) == frozenset({400.0})
    assert m.waiting(370.0, 0.0, W, (walker(401.5, edge + 0.01),)) == frozenset()  # too far
    assert m.waiting(370.0, 0.0, W, (walker(400.0 - P.crossing_margin - 0.01, -5.0),)) \
        == frozenset()  # before the crosswalk along the road
    assert m.waiting(370.0, 0.0, W, (walker(404.0 + P.crossing_margin, -5.0),)) \
        == frozenset({400.0})  # just past its far edge, within the margin
    assert m.waiting(397.7, 0.0, W, (kerb,)) == frozenset()  # the front bumper on it
    assert m.waiting(370.0, 0.0, W, ()) == frozenset()


def test_the_car_yields_to_a_pedestrian_crossing_towards_its_lane_while_it_can_stop() -> None:
    """A walker stepping off the far kerb (6.5 m left of the lane's centre) at 1.1 m/s is in
    the lane's band (its half width + `lane_margin`) only some 2.5 s later, when the stop
    left from 20 km/h is a hard one. The car yields as soon as it walks in while a stop at
    `a_comf` is left, holds the yield while it walks in (the stop no longer comfortable as
    the car brakes late in a test), and not for a walker who stands or walks away, nor when
    the stop left is no longer comfortable as the walker starts."""
    v = 20.0 * KPH
    far_kerb = walker(402.0, 6.5, vy=-1.1)
    m = EventMonitor(ROAD, VEHICLE, P)
    assert 6.5 - P.look_ahead * 1.1 > 0.5 * W + P.lane_margin  # the band rule alone: none
    yielding = at(m, 370.0, v, tracks=(far_kerb,))
    assert yielding.holds(PEDESTRIAN)
    assert yielding.stop_distance == pytest.approx(400.0 - 372.4 - P.crossing_stop)
    assert at(m, 392.0, v, tracks=(walker(402.0, 5.0, vy=-1.1),)).holds(PEDESTRIAN)  # held
    assert not at(m, 392.0, v, tracks=(walker(402.0, 5.0),)).holds(PEDESTRIAN)  # it stopped
    late = EventMonitor(ROAD, VEHICLE, P)
    assert not at(late, 392.0, v, tracks=(far_kerb,)).holds(PEDESTRIAN)  # no comfortable stop
    other = EventMonitor(ROAD, VEHICLE, P)
    assert not at(other, 370.0, v, tracks=(walker(402.0, 6.5),)).holds(PEDESTRIAN)  # stands
    assert not at(other, 370.0, v, tracks=(walker(402.0, 6.5, vy=1.1),)).holds(PEDESTRIAN)
    assert not at(other, 370.0, v, tracks=(walker(402.0, 6.5, vy=-0.4),)).holds(PEDESTRIAN)
    beyond = 0.5 * W + P.waiting_reach + 0.5  # [m] farther out than a walker waiting
    assert not at(other, 370.0, v, tracks=(walker(402.0, beyond, vy=-1.1),)).holds(PEDESTRIAN)


def test_a_pedestrian_at_the_crossing_counts_within_the_stations_uncertainty() -> None:
    """The car's station is off by up to `station_sigmas` x its 1-sigma along the route, and
    the tracks placed with it by as much: a walker truly on the crosswalk's near edge (400.2
    m) stepping into the lane appears 2.4 m short of it under a consumer receiver (1.2 m
    1-sigma, the car 2.4 m further on than it believes). That walker counts, and the car
    stops 2.5 x 1.2 m before the crosswalk in its estimate (not `crossing_stop`), so that
    where it truly stands is still before the crosswalk."""
    m = EventMonitor(ROAD, VEHICLE, P)
    seen = walker(400.2 - 2.4, -4.5, vy=1.2)
    sure = m.update(0.0, 370.0, 8.0, 0.0, W, (seen,))
    assert not sure.holds(PEDESTRIAN)  # the station taken as exact: not at the crossing
    unsure = m.update(0.0, 370.0, 8.0, 0.0, W, (seen,), station_sigma=1.2)
    assert unsure.holds(PEDESTRIAN)
    slack = P.station_sigmas * 1.2
    assert slack > P.crossing_stop
    assert unsure.stop_distance == pytest.approx(400.0 - 372.4 - slack)
    truly = 370.0 + 2.4 + VEHICLE.front_overhang + unsure.stop_distance  # [m] front bumper
    assert truly < 400.0  # truly before the crosswalk
    far = walker(400.0 - P.crossing_margin - slack - 0.01, -4.5, vy=1.2)  # beyond the slack
    assert not m.update(0.0, 370.0, 8.0, 0.0, W, (far,), station_sigma=1.2).holds(PEDESTRIAN)
    assert m.waiting(370.0, 0.0, W, (seen,)) == frozenset()
    assert m.waiting(370.0, 0.0, W, (seen,), station_sigma=1.2) == frozenset({400.0})
