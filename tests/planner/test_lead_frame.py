"""Beyond the camera's reach the lane the lead is looked for in is the map's lane bent from
its tangent at the car's station at the camera frame's time, the frame the camera's lane and
the tracks are in (`Planner._bend`, `planner.lead.far_centre`). In a tight bend the car
turns while a frame ages: a tangent taken at the car's station now places the lane ahead,
beyond the bend, towards its outside, onto a car keeping the lane beside."""

from __future__ import annotations

import math

from perception.messages import EgoState, LaneEstimate, LaneView, ObjectClass, PlannerInput, Track
from planner.planner import Planner, PlannerParams
from tests.planner.maps import KPH
from tests.roads import arc, make_map, seg
from tests.vehicle import VEHICLE

RADIUS = 50.0  # [m] a right bend of 80 degrees, then a straight
ROAD = make_map(seg(100.0), arc(RADIUS, -80.0), seg(300.0))  # normal_driving's bend
V_EGO = 12.5  # [m/s] the car in the bend (45 km/h)
V_OTHER = 8.3  # [m/s] the other car (lane 1 is left of the ego's lane 0)
AGE = 0.175  # [s] the camera frame's and the tracks' age at each tick (0.1 to 0.175 s in
#   normal_driving: LiDAR scan and camera frame at 10 Hz, their processing)
DT = 0.05  # [s] planner tick


def pose(s: float, t: float) -> EgoState:
    """The car on lane 0's centre at station `s` [m], at time `t` [s]."""
    lane = ROAD.lane(0)
    xy = lane.position(s, 0.0)
    heading = float(lane.heading_at(s))
    return EgoState(t, float(xy[0]), float(xy[1]), heading, V_EGO, -V_EGO / RADIUS, 0.0, 0.1)


def tracked(at: EgoState, index: int, s: float, ident: int = 7) -> Track:
    """A car on lane `index`'s centre at station `s` [m], tracked (id `ident`) at the time
    of `at` in its vehicle frame."""
    lane = ROAD.lane(index)
    xy = lane.position(s, 0.0)
    h = float(lane.heading_at(s))
    vx, vy = V_OTHER * math.cos(h), V_OTHER * math.sin(h)
    c, sn = math.cos(at.heading), math.sin(at.heading)
    dx, dy = float(xy[0]) - at.x, float(xy[1]) - at.y
    ex, ey = at.speed * c, at.speed * sn
    return Track(ident, at.t, float(xy[0]), float(xy[1]), vx, vy,
                 c * dx + sn * dy, -sn * dx + c * dy,
                 c * (vx - ex) + sn * (vy - ey), -sn * (vx - ex) + c * (vy - ey),
                 4.77, 1.83, 1.46, h, ObjectClass.CAR, 20, 0, 0.2)


def seen_from(at: EgoState) -> LaneView:
    """The camera's lane at pose `at`, exact: the car on its centre, along it, in the bend."""
    return LaneView(LaneEstimate(t=at.t, offset=0.0, heading_error=0.0,
                                 curvature=-1.0 / RADIUS, width=3.5, confidence=0.9,
                                 left=None, right=None), at)


def leads_through_the_bend(lane: int) -> list[int | None]:
    """The lead's track id each tick over 1.6 s: the car 35 to 54 m into the 70 m of the
    bend at 45 km/h, the other car on `lane` 65 to 59 m ahead along it (on the straight
    after the bend), the camera's frame, exact, and the track `AGE` old."""
    planner = Planner(ROAD, PlannerParams(50.0 * KPH, 180.0 * KPH, VEHICLE, lane=0,
                                          camera=True))
    leads: list[int | None] = []
    for k in range(int(1.6 / DT)):
        t = 10.0 + k * DT
        s_frame = 135.0 + V_EGO * (t - AGE - 10.0)  # the car's station at the frame's time
        frame = pose(s_frame, t - AGE)
        other = tracked(frame, lane, s_frame + 65.0 - (V_EGO - V_OTHER) * (t - AGE - 10.0))
        assert other.rel_x > 30.0  # beyond the camera's reach: the map's bend
        plan = planner.update(PlannerInput(pose(s_frame + V_EGO * AGE, t),
                                           lane=seen_from(frame), tracks=(other,)))
        leads.append(None if plan.lead is None else plan.lead.track_id)
    return leads


def test_a_car_keeping_the_lane_beside_through_a_tight_bend_is_never_the_lead() -> None:
    """The frame 0.175 s old, the car's heading has turned 0.044 rad since: the tangent at
    the car's station now placed the car beside 1.55 to 1.7 m from the lane's centre line
    (3.3 to 3.7 m from the frame's), and it was the lead from 0.6 to 0.95 s."""
    assert leads_through_the_bend(1) == [None] * int(1.6 / DT)


def test_a_car_in_the_lane_through_the_same_bend_is_the_lead() -> None:
    """The same run with the other car in the car's own lane: the lead after `confirm`, and
    kept (with the tangent at the station now it was placed 2.5 to 2.7 m right of the
    centre line, out of the lane, and taken only after 1.4 s)."""
    leads = leads_through_the_bend(0)
    first = leads.index(7)
    assert leads[:first] == [None] * first and set(leads[first:]) == {7}
    assert first * DT <= 0.3 + 1e-9
