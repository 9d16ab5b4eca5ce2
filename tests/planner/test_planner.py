"""The planner's tick: station, lateral error, path window, speed target and what set it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from perception.messages import EgoState, ObjectClass, PlannerInput, Track
from planner.fsm.acc import AccMode
from planner.fsm.motion import Motion
from planner.messages import Lead, Plan, SpeedSource
from planner.motion_layer import Manoeuvre
from planner.planner import Planner, PlannerParams, _with_room
from planner.speed_planning import Binding, SpeedPlanner
from tests.planner.maps import KPH, real_map, road_spec, segment, straight_road
from tests.vehicle import VEHICLE
from world.hdmap import RoadMap

KINDS = ["real"]  # the planner now needs the whole map (lanes, projection)


def ego_on(road: RoadMap, lane: int, s: float, r: float, speed: float, t: float = 1.0) -> EgoState:
    xy = road.lane(lane).position(s, r)
    heading = float(road.lane(lane).heading_at(s))
    heading = math.remainder(heading, 2.0 * math.pi)
    return EgoState(t, float(xy[0]), float(xy[1]), heading, speed, 0.0, 0.0, 0.1)


def planner(road: RoadMap, lane: int = 1, set_kph: float = 80.0,
            camera: bool = False) -> Planner:
    """The map-only planner by default (these tests are about the map path and speed)."""
    return Planner(road, PlannerParams(set_kph * KPH, 180.0 * KPH, VEHICLE, lane=lane,
                                       camera=camera))


def test_plan_on_an_arc() -> None:
    road = real_map(road_spec([segment(100.0), segment(200.0, 60.0), segment(100.0)], 100.0))
    p = planner(road)
    ego = ego_on(road, 1, 150.0, 0.4, 20.0, t=3.5)
    plan = p.update(PlannerInput(ego))
    assert plan.t == 3.5
    assert plan.ego is ego
    assert plan.station == pytest.approx(150.0)
    assert plan.lateral_error == pytest.approx(0.4)
    lane = road.lane(1)
    s, r = lane.local_coordinates(plan.path.xy)
    np.testing.assert_allclose(r, 0.0, atol=1e-9)
    assert s[0] == pytest.approx(145.0)
    assert s[-1] == pytest.approx(150.0 + 2.5 * 20.0)  # 2.5 s at 20 m/s > 25 m
    # the speed target is the speed planner's, for the same station
    expected = SpeedPlanner(road, lane, p.params.speed, VEHICLE).target(
        150.0, set_speed=80.0 * KPH, max_speed=180.0 * KPH
    )
    assert plan.target_speed == pytest.approx(expected.speed)
    assert plan.target_speed == pytest.approx(math.sqrt(3.0 * 56.5))
    assert plan.target_accel == 0.0
    assert plan.speed_limit == pytest.approx(100.0 * KPH)
    assert p.speed_for(150.0).binding is Binding.CURVE
    assert plan.speed_source is SpeedSource.CURVE


@pytest.mark.parametrize("kind", KINDS)
def test_plan_on_a_straight(kind: str) -> None:
    road = straight_road(kind, 1000.0, 50.0, ((400.0, 30.0),))
    p = planner(road, lane=0)
    p.update(PlannerInput(ego_on(road, 0, 200.0, -0.25, 3.0, t=0.0)))  # engaged at 0 s ...
    plan = p.update(PlannerInput(ego_on(road, 0, 200.0, -0.25, 3.0, t=1.0)))  # ... 1 s on
    assert plan.station == pytest.approx(200.0)
    assert plan.lateral_error == pytest.approx(-0.25)
    assert plan.path.xy[0, 0] == pytest.approx(195.0)
    assert plan.path.xy[-1, 0] == pytest.approx(225.0)  # at least 25 m ahead
    assert plan.target_speed == pytest.approx(49.7 * KPH)
    assert plan.speed_limit == pytest.approx(50.0 * KPH)
    assert plan.speed_source is SpeedSource.LIMIT
    ahead = p.update(PlannerInput(ego_on(road, 0, 400.0 - 2.4 - 20.0, 0.0, 13.8, t=2.0)))
    assert ahead.target_accel == -1.5
    assert ahead.speed_source is SpeedSource.LIMIT  # braking towards the lower posting
    assert ahead.speed_limit == pytest.approx(50.0 * KPH)


@pytest.mark.parametrize("kind", KINDS)
def test_closed_loop_point_mass_through_posting(kind: str) -> None:
    """A perfect follower driving the planner's targets on lane 1 respects the new limit
    from the moment its front bumper passes the sign."""
    sign = 300.0
    road = straight_road(kind, 600.0, 50.0, ((sign, 30.0),))
    p = planner(road, lane=1, set_kph=60.0)
    p.reset()
    dt = 1.0 / 40.0
    s, v, t = 100.0, 49.7 * KPH, 0.0
    while s < 420.0:
        plan = p.update(PlannerInput(ego_on(road, 1, s, 0.0, v, t)))
        assert v - plan.target_speed <= (1.5 + 0.02) * dt  # decel <= a_comf + small
        if plan.station + 2.4 >= sign:
            assert plan.target_speed <= 30.0 * KPH
        s += 0.5 * (v + plan.target_speed) * dt
        v = plan.target_speed
        t += dt
    assert v == pytest.approx(29.7 * KPH)


def test_rejects_oncoming_lane() -> None:
    road = straight_road("real", 100.0, 50.0)
    with pytest.raises(ValueError, match="ego-direction"):
        Planner(road, PlannerParams(10.0, 20.0, VEHICLE, lane=-1))


def test_with_a_flat_tyre_rear_traffic_is_judged_at_the_speed_flat_slows_to() -> None:
    """FLAT slows at ``a_flat_plan`` (2 m/s^2) to its crawl (6 m/s): over the longest lane
    change (5 s) from 16 m/s the car ends at 6 m/s, from 25 m/s at 15 m/s."""
    p = planner(straight_road("real", 500.0, 90.0), lane=0)
    assert p._lowest_speed(16.0, flat=False) == 16.0
    assert p._lowest_speed(16.0, flat=True) == pytest.approx(6.0)
    assert p._lowest_speed(25.0, flat=True) == pytest.approx(15.0)
    assert p._lowest_speed(4.0, flat=True) == pytest.approx(4.0)


def test_the_acc_sees_a_stationary_car_it_may_pass_nearer_by_the_room() -> None:

    lead = Lead(7, 1.0, 20.0, 0.0)
    room = Manoeuvre(Motion.LANE_KEEP, 0, 0, None, room=8.0, room_for=7)
    assert _with_room(lead, room) == Lead(7, 1.0, 12.0, 0.0)
    other = Manoeuvre(Motion.LANE_KEEP, 0, 0, None, room=8.0, room_for=3)
    assert _with_room(lead, other) is lead
    assert _with_room(None, room) is None


def _car_ahead(road: RoadMap, s: float, speed: float, ego: EgoState) -> Track:
    """A confirmed car track centred at station `s` of lane 1, at `speed` along it (the
    straight road runs along +x)."""
    x, y = (float(c) for c in road.lane(1).position(s, 0.0))
    return Track(id=9, t=ego.t, x=x, y=y, vx=speed, vy=0.0, rel_x=x - ego.x, rel_y=y - ego.y,
                 rel_vx=speed - ego.speed,
                 rel_vy=0.0, length=4.6, width=1.8, height=1.5, yaw=0.0, cls=ObjectClass.CAR,
                 hits=20, misses=0, position_sigma=0.1)


def test_not_engaged_the_driver_holds_the_set_speed_whatever_is_ahead() -> None:
    """Before the function is switched on the ACC is off and the set speed is held, a slower
    car 40 m ahead notwithstanding; switched on, the ACC takes it as its lead at once."""
    road = straight_road("real", 1000.0, 100.0)
    p = planner(road, set_kph=72.0)

    def tick(k: int, engaged: bool) -> Plan:
        t = 1.0 + 0.1 * k
        ego = ego_on(road, 1, 100.0 + 20.0 * (t - 1.0), 0.0, 20.0, t)
        car = _car_ahead(road, 145.0 + 10.0 * (t - 1.0), 10.0, ego)
        return p.update(PlannerInput(ego, tracks=(car,), engaged=engaged))

    for k in range(8):
        plan = tick(k, engaged=False)
        assert plan.acc_mode is AccMode.ACC_OFF and plan.speed_source is SpeedSource.DRIVER
        assert plan.target_speed == pytest.approx(20.0) and plan.target_accel == 0.0
    assert plan.lead is not None  # seen all along
    plan = tick(8, engaged=True)
    assert plan.acc_mode is not AccMode.ACC_OFF and plan.lead is not None
    assert plan.speed_source is SpeedSource.FOLLOWING and plan.target_speed < 20.0
    assert [c.source for c in plan.changes if c.machine == "acc"] == ["acc_off"]


@pytest.mark.parametrize(("set_kph", "source"), [(100.0, SpeedSource.SIGHT),
                                                  (80.0, SpeedSource.SET_SPEED)])
def test_the_sight_cap_is_its_own_speed_source(set_kph: float, source: SpeedSource) -> None:
    """A set speed above what the forward sensing range covers (about 91 km/h) is capped,
    and the plan says the sight cap set the speed, not the set speed; below it the set
    speed binds."""
    road = straight_road("real", 2000.0, 130.0)
    p = planner(road, lane=0, set_kph=set_kph)
    p.update(PlannerInput(ego_on(road, 0, 200.0, 0.0, 25.0, t=0.0)))  # engaged at 0 s ...
    plan = p.update(PlannerInput(ego_on(road, 0, 200.0, 0.0, 25.0, t=1.0)))  # ... 1 s on
    assert plan.target_speed == pytest.approx(min(set_kph * KPH, p.sight_speed))
    assert 90.0 * KPH < p.sight_speed < 92.0 * KPH
    assert plan.speed_source is source
    assert p.speed_for(200.0).binding is (Binding.SIGHT if source is SpeedSource.SIGHT
                                          else Binding.SET_SPEED)


def test_not_engaged_after_the_aeb_stops_the_car_the_driver_holds_it_until_the_way_is_clear(
        ) -> None:
    """The driver holds his set speed whatever is ahead; the AEB stops the car short of a
    standing car; he does not drive off into it, only once it moves away."""
    road = straight_road("real", 1000.0, 100.0)
    p = planner(road, set_kph=50.0)

    def tick(t: float, s: float, v: float, car_s: float, car_v: float) -> Plan:
        ego = ego_on(road, 1, s, 0.0, v, t)
        return p.update(PlannerInput(ego, tracks=(_car_ahead(road, car_s, car_v, ego),),
                                     engaged=False))

    plan = tick(1.0, 100.0, 10.0, 112.0, 0.0)  # 7.4 m gap at 10 m/s: the AEB brakes
    assert plan.speed_source is SpeedSource.EMERGENCY
    for k in range(40):  # stopped 1.5 m short of it, for 2 s
        plan = tick(1.1 + 0.05 * k, 104.0, 0.0, 112.0, 0.0)
        assert plan.target_speed == 0.0 and plan.speed_source is SpeedSource.DRIVER, k
    assert "acceleration" not in [c.target for c in plan.changes if c.machine == "control"]
    for k in range(20):  # it moves off at 2 m/s: so does the driver, at his rate
        plan = tick(3.1 + 0.05 * k, 104.0, 0.0, 112.0 + 0.1 * k, 2.0)
    assert plan.target_speed > 0.0
