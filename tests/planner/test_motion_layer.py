"""The motion layer on a straight two-lane road with synthetic tracks: it overtakes a
blocking car when the left lane is free, follows the Hermite path into it, is done at its
end, and aborts back to its lane when a fast car comes up behind in the target lane."""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np
import pytest

from perception.messages import EgoState, ObjectClass, Track
from planner.fsm.acc import AccParams
from planner.fsm.motion import Motion
from planner.lane_occupancy import (
    Neighbour,
    OccupancyParams,
    lane_traffic,
    rear_closes,
    rear_decel_needed,
)
from planner.motion_layer import MotionLayer, MotionLayerParams, room_left
from tests.roads import W, make_map, seg
from tests.vehicle import VEHICLE
from world.hdmap import SHOULDER, Manoeuvre, Side
from world.map.road import build_road_map
from world.map.town import TownLayout, compile_route
from world.spec import TownSpec

ROAD = make_map(seg(1000.0))
V = 13.9  # [m/s]


def ego(t: float, x: float, y: float = 0.0) -> EgoState:
    return EgoState(t=t, x=x, y=y, heading=0.0, speed=V, yaw_rate=0.0, steering_angle=0.0,
                    position_sigma=0.05)


def car(t: float, x: float, y: float, vx: float, ident: int) -> Track:
    return Track(id=ident, t=t, x=x, y=y, vx=vx, vy=0.0, rel_x=0.0, rel_y=0.0, rel_vx=0.0,
                 rel_vy=0.0, length=4.6, width=1.8, height=1.5, yaw=0.0, cls=ObjectClass.CAR,
                 hits=9, misses=0, position_sigma=0.1)


def layer(overtake: bool = True) -> MotionLayer:
    return MotionLayer(ROAD, 0, AccParams(), VEHICLE, MotionLayerParams(overtake=overtake))


def drive(m: MotionLayer, t0: float, t1: float, slow_x0: float,
          fast: tuple[float, float] | None = None) -> list[tuple[float, Motion, int]]:
    """Step from t0 to t1 at 40 Hz with the ego on the plan's path (perfect tracking) and
    a 20 km/h car ahead in lane 0; `fast` = (x at t0, speed) of a car in lane 1."""
    out, t, x, y = [], t0, 100.0 + V * t0, 0.0
    while t < t1:
        tracks = [car(t, slow_x0 + 5.56 * t, 0.0, 5.56, 1)]
        if fast is not None:
            tracks.append(car(t, fast[0] + fast[1] * (t - t0), W, fast[1], 2))
        man, _ = m.update(ego(t, x, y), V, tracks)
        if man.path is not None:
            y = float(ROAD.lane(man.path.target_index).offset_at(x)) + float(
                man.path.offset_at(x))
        out.append((t, man.motion, man.lane))
        t += 0.025
        x += V * 0.025
    return out


def test_overtakes_a_blocking_car_when_the_left_lane_is_free() -> None:
    m = layer()
    steps = drive(m, 0.0, 8.0, slow_x0=170.0)
    motions = [s[1] for s in steps]
    start = motions.index(Motion.LANE_CHANGE_LEFT)
    assert steps[start][0] == pytest.approx(1.0, abs=0.05)  # blocked for blocked_time
    end = start + motions[start:].index(Motion.LANE_KEEP)
    duration = steps[end][0] - steps[start][0]
    assert m.path is None and steps[-1][2] == 1 and m.origin == 1
    assert 4.0 < duration < 5.5  # the path's length at this speed


def test_after_passing_it_keeps_right_once_the_passed_car_is_far_enough_behind() -> None:
    """Back to lane 0 `keep_time` after the pass is done and with the passed car at least
    `keep_right_gap` (2 s) behind; once, and to stay (no weaving)."""
    m = layer()
    steps = drive(m, 0.0, 20.0, slow_x0=170.0)
    runs = [steps[0][1]] + [b[1] for a, b in itertools.pairwise(steps)
                            if b[1] is not a[1]]
    assert runs == [Motion.LANE_KEEP, Motion.LANE_CHANGE_LEFT, Motion.LANE_KEEP,
                    Motion.LANE_CHANGE_RIGHT, Motion.LANE_KEEP]
    motions = [s[1] for s in steps]
    left_done = motions.index(Motion.LANE_KEEP, motions.index(Motion.LANE_CHANGE_LEFT))
    back = motions.index(Motion.LANE_CHANGE_RIGHT)
    t_back = steps[back][0]
    assert t_back - steps[left_done][0] >= 3.0 - 1e-9  # keep_time
    ego_rear = 100.0 + V * t_back - VEHICLE.rear_overhang
    slow_front = 170.0 + 5.56 * t_back + 2.3
    assert ego_rear - slow_front >= V * 2.0  # keep_right_gap behind
    assert steps[-1][2] == 0 and m.path is None


def test_follows_when_overtaking_is_not_allowed() -> None:
    steps = drive(layer(overtake=False), 0.0, 5.0, slow_x0=170.0)
    assert {s[1] for s in steps} == {Motion.LANE_KEEP}


def test_waits_while_a_fast_car_comes_up_in_the_left_lane() -> None:
    steps = drive(layer(), 0.0, 3.0, slow_x0=170.0, fast=(60.0, 25.0))
    assert {s[1] for s in steps} == {Motion.LANE_KEEP}


def test_aborts_when_the_target_lane_stops_being_free() -> None:
    m = layer()
    drive(m, 0.0, 1.2, slow_x0=170.0)
    assert m.motion is Motion.LANE_CHANGE_LEFT and m.lane == 1
    # a car at 30 m/s appears 40 m behind in the target lane: it would have to brake hard
    steps = drive(m, 1.2, 1.5, slow_x0=170.0, fast=(100.0 + V * 1.2 - 45.0, 30.0))
    assert steps[-1][1] is Motion.LANE_KEEP and steps[-1][2] == 0  # back to lane 0
    assert m.path is not None and m.path.target_index == 0  # on the way back
    assert m.origin == 1  # both lanes in use until the path's end


def test_moves_to_the_lane_that_goes_on_before_an_exit() -> None:
    ramp = replace(seg(100.0, lanes=1, oncoming=0), exit=Side.RIGHT)
    road = make_map(seg(600.0), ramp)
    # no overtaking: a route need
    m = MotionLayer(road, 1, AccParams(), VEHICLE, MotionLayerParams())
    far = m.update(ego(0.0, 100.0 + V * 0.0, W), V, [])[0]  # 500 m before the fork
    assert far.motion is Motion.LANE_KEEP
    man, changes = m.update(ego(1.0, 450.0, W), V, [])  # 150 m before it
    assert man.motion is Motion.LANE_CHANGE_RIGHT and man.lane == 0 and man.origin == 1
    assert "route" in changes[0].reason


def test_a_flat_tyre_pulls_over_lane_by_lane_onto_the_shoulder() -> None:
    m = MotionLayer(ROAD, 1, AccParams(), VEHICLE, MotionLayerParams())
    t, x, y, lanes, caps = 0.0, 100.0, W, [], set()
    while t < 20.0:
        man, _ = m.update(ego(t, x, y), V, [], pull_over=True)
        if man.path is not None:
            y = float(ROAD.lane(man.path.target_index).offset_at(x)) + float(
                man.path.offset_at(x))
        lanes.append(man.lane)
        caps.add(man.speed_cap)
        t, x = t + 0.025, x + V * 0.025
    assert caps == {math.inf}  # the shoulder (a negative index too) is no oncoming lane
    assert lanes[0] == 0 and lanes[-1] == SHOULDER  # lane 1 -> 0 -> the shoulder
    assert sorted(set(lanes), key=lanes.index) == [0, SHOULDER]
    assert m.motion is Motion.LANE_KEEP and m.path is None
    assert y == pytest.approx(float(ROAD.shoulder.offset_at(x)))


def test_a_pull_over_waits_for_a_car_coming_up_in_the_lane_it_must_cross() -> None:
    """A flat tyre's crawl (6 m/s) in lane 1, a car at 51 km/h 56 m behind in lane 0 that
    never brakes: the move into lane 0 alone would be over before it arrives (UN R157's
    rear rule holds for it), but the car then waits there and crosses on to the shoulder
    at 6 m/s, and the car behind, keeping its speed, runs into it. It pulls over once the
    car has gone by, and is never in lane 0 with it closing in behind."""
    v, u, gap0 = 6.0, 14.2, 56.5  # [m/s], [m/s], [m] from the car's front to the ego's rear
    m = MotionLayer(ROAD, 1, AccParams(), VEHICLE, MotionLayerParams())
    t, x, y, first_in_lane0 = 0.0, 200.0, W, None
    while t < 30.0:
        behind_x = x - VEHICLE.rear_overhang - gap0 - 2.3 + (u - v) * t  # its centre
        pose = EgoState(t=t, x=x, y=y, heading=0.0, speed=v, yaw_rate=0.0,
                        steering_angle=0.0, position_sigma=0.05)
        man, _ = m.update(pose, v, [car(t, behind_x, 0.0, u, 7)], pull_over=True, v_rear=v)
        if man.path is not None:
            y = float(ROAD.lane(man.path.target_index).offset_at(x)) + float(
                man.path.offset_at(x))
        if first_in_lane0 is None and man.lane == 0:
            first_in_lane0 = (t, behind_x)
        t, x = t + 0.025, x + v * 0.025
    assert first_in_lane0 is not None and m.lane == SHOULDER  # it did pull over, later
    t_in, behind_then = first_in_lane0
    assert behind_then - 2.3 > (x - v * (30.0 - t_in)) + VEHICLE.front_overhang  # gone by


@pytest.mark.parametrize(
    ("manoeuvre", "state"),
    [("left", Motion.TURN_LEFT), ("right", Motion.TURN_RIGHT), ("u_turn", Motion.U_TURN)],
)
def test_a_town_turn_from_the_stop_line_to_the_junction_exit(manoeuvre: str,
                                                             state: Motion) -> None:
    layout = TownLayout(TownSpec(3, 2, 90.0, 2, 3.5, 11.0, "stop_signs"))
    road = build_road_map(compile_route(layout, (0, 1, "east"), (Manoeuvre(manoeuvre),), "e"))
    j = road.junctions[0]
    m = MotionLayer(road, 0, AccParams(), VEHICLE, MotionLayerParams())
    seen = []
    for k, s in enumerate(np.arange(j.s_stop - 10.0, j.s_exit + 10.0, 0.5)):
        x, y = road.position(s, 0.0)
        pose = EgoState(t=0.1 * k, x=float(x), y=float(y), heading=float(road.heading_at(s)),
                        speed=4.0, yaw_rate=0.0, steering_angle=0.0, position_sigma=0.1)
        manoeuvre_now, _ = m.update(pose, 4.0, ())
        seen.append((float(s), manoeuvre_now.motion))
    turning = [s for s, motion in seen if motion is state]
    assert turning[0] == pytest.approx(j.s_stop, abs=0.5)
    assert turning[-1] == pytest.approx(j.s_exit, abs=0.6)
    assert seen[-1][1] is Motion.LANE_KEEP
    assert all(motion in (state, Motion.LANE_KEEP) for _, motion in seen)


def test_a_pass_does_not_trail_the_car_it_clears() -> None:
    """During the pass, the slow car ahead in the origin lane (closing at 8.3 m/s) is no
    lead: the path clears it (issue K, item 6: the pass does not trail the car it leaves)."""
    m = layer()
    t, x, y = 0.0, 100.0, 0.0
    seen: list[bool] = []  # the slow car a lead, on the path
    while t < 8.0:
        slow = car(t, 170.0 + 5.56 * t, 0.0, 5.56, 1)
        man, _ = m.update(ego(t, x, y), V, [slow])
        if man.motion is Motion.LANE_CHANGE_LEFT:
            assert man.path is not None and m.clears(man.path, _ahead(m, t, x, y, slow), x, V)
            seen.append(any(n.track_id == 1 for n in man.leads))
        if man.path is not None:
            y = float(ROAD.lane(man.path.target_index).offset_at(x)) + float(
                man.path.offset_at(x))
        t += 0.025
        x += V * 0.025
    assert len(seen) > 100 and not any(seen)


def test_a_pass_trails_the_car_it_leaves_once_the_path_would_not_clear_it() -> None:
    """The car being passed stops short early in the change: from then on the path would
    not clear it, and it is a lead (the ACC stops the car behind it rather than into it)
    while the body still overlaps its lane."""
    m = layer()
    t, x, y = 0.0, 100.0, 0.0
    stop_x: float | None = None
    leads: list[bool] = []
    while t < 3.0:
        if stop_x is None:
            slow = car(t, 170.0 + 5.56 * t, 0.0, 5.56, 1)
        else:
            slow = car(t, stop_x, 0.0, 0.0, 1)
        man, _ = m.update(ego(t, x, y), V, [slow])
        if man.motion is Motion.LANE_CHANGE_LEFT:
            if stop_x is None:  # it stops 20 m ahead of the car's front
                stop_x = x + VEHICLE.front_overhang + 20.0 + 2.3
            elif x + VEHICLE.front_overhang < stop_x - 2.3:  # still ahead of the car
                leads.append(any(n.track_id == 1 for n in man.leads))
        if man.path is not None:
            y = float(ROAD.lane(man.path.target_index).offset_at(x)) + float(
                man.path.offset_at(x))
        t += 0.025
        x += V * 0.025
    assert leads and all(leads)


def _ahead(m: MotionLayer, t: float, x: float, y: float, track: Track) -> Neighbour:
    """`track` as the motion layer sees it in lane 0 (its neighbour there)."""
    traffic = lane_traffic(ROAD, [track], t, x, (0, 1), m.params.occupancy, VEHICLE)
    n = traffic[0].ahead
    assert n is not None
    return n


def standing(t: float, x: float) -> EgoState:
    return EgoState(t=t, x=x, y=0.0, heading=0.0, speed=0.0, yaw_rate=0.0,
                    steering_angle=0.0, position_sigma=0.05)


def stopped_car(t: float, gap: float) -> Track:
    """A car standing in lane 0 `gap` [m] ahead of the front of an ego whose centre is at
    x = 100 m."""
    return car(t, 100.0 + VEHICLE.front_overhang + gap + 2.3, 0.0, 0.0, 7)


@pytest.mark.parametrize(("gap", "passes"), [(12.0, True), (9.0, True), (6.0, False),
                                             (4.0, False)])
def test_passes_a_stopped_car_from_a_standstill_only_with_room_to_pull_out(
        gap: float, passes: bool) -> None:
    """Standing behind a stopped car, the left lane free: the pass (a path of `min_length`)
    starts once `blocked_time` has passed if it clears the car, from the `pass_gap` the ACC
    keeps behind it (12 m) and a little nearer, but not from the ACC's d0 (4 m)."""
    m = layer()
    motions = [m.update(standing(t, 100.0), V, [stopped_car(t, gap)])[0].motion
               for t in np.arange(0.0, 2.0, 0.025)]
    assert (Motion.LANE_CHANGE_LEFT in motions) is passes
    if passes:
        assert motions.index(Motion.LANE_CHANGE_LEFT) * 0.025 == pytest.approx(1.0, abs=0.05)


def test_a_pass_from_a_standstill_waits_for_a_car_coming_up_behind() -> None:
    """A car at 60 km/h 30 m behind in the left lane would have to brake at 5.4 m/s^2 if the
    standing car pulled out: it waits; once that car has gone by, it goes."""
    m = layer()
    seen = []
    for t in np.arange(0.0, 6.0, 0.025):
        rear = car(t, 100.0 - 30.0 - 4.7 + 16.7 * t, W, 16.7, 8)
        seen.append((t, m.update(standing(t, 100.0), V, [stopped_car(t, 10.0), rear])[0]))
    start = next(t for t, man in seen if man.motion is Motion.LANE_CHANGE_LEFT)
    rear_front_passes = (30.0 + 4.7) / 16.7  # [s] its rear bumper passes the ego's front
    assert start > rear_front_passes


def test_keeps_room_behind_a_stationary_car_it_may_pass() -> None:
    """Overtaking on, a stationary car blocking the lane: the ACC is to keep `pass_gap` (12
    m) instead of d0 (4 m) behind it; not without overtaking, nor behind a moving car."""
    acc = AccParams()
    man = layer().update(standing(0.0, 100.0), V, [stopped_car(0.0, 12.0)])[0]
    assert man.room_for == 7 and man.room == pytest.approx(12.0 - acc.d0)
    off = layer(overtake=False).update(standing(0.0, 100.0), V, [stopped_car(0.0, 12.0)])[0]
    assert off.room_for is None and off.room == 0.0
    moving = layer().update(ego(0.0, 100.0), V, [car(0.0, 140.0, 0.0, 5.56, 1)])[0]
    assert moving.room_for is None
    one_lane = make_map(seg(1000.0, lanes=1, oncoming=0))
    alone = MotionLayer(one_lane, 0, acc, VEHICLE, MotionLayerParams(overtake=True)).update(
        standing(0.0, 100.0), V, [stopped_car(0.0, 12.0)])[0]
    assert alone.room_for is None  # no lane to pass in


def test_the_room_is_what_a_gentle_stop_leaves() -> None:
    """Coming up at 13.9 m/s, 50 m behind the stopped car: a stop at `room_decel` (2.5
    m/s^2) takes 38.6 m, so 50 - 4 - 38.6 = 7.4 m of room (not the 8 m of `pass_gap`)."""
    man = layer().update(ego(0.0, 100.0), V, [stopped_car(0.0, 50.0)])[0]
    assert man.room == pytest.approx(50.0 - 4.0 - V**2 / 5.0, abs=0.05)


def test_the_room_granted_is_kept_through_a_gentler_stop() -> None:
    """The 7.4 m granted 50 m behind the stopped car at 13.9 m/s stay granted while the car
    brakes at 1.5 m/s^2 (gentler than `room_decel`): what a stop at 2.5 m/s^2 would leave
    from there shrinks every tick (to 50 - 11.9 - 4 - 12.6^2 / 5 = 2.4 m after 0.9 s, the
    pass not yet started), which would bring the car to its d0, where no pass path clears
    the car."""
    m, t, x, v = layer(), 0.0, 100.0, V
    first = m.update(ego(0.0, x), V, [stopped_car(0.0, 50.0)])[0].room
    rooms = []
    while t < 0.9:
        t, x, v = t + 0.025, x + v * 0.025, v - 1.5 * 0.025
        state = replace(ego(t, x), speed=v)
        track = stopped_car(t, 50.0)  # at x = 100 + front overhang + 50 + 2.3: it stands
        rooms.append(m.update(state, V, [track])[0].room)
    assert first == pytest.approx(50.0 - 4.0 - V**2 / 5.0, abs=0.05)
    assert rooms == pytest.approx([first] * len(rooms))


@pytest.mark.parametrize("gap", [20.0, 27.0, 32.0])
def test_a_late_reveal_keeps_room_at_a_hard_stop(gap: float) -> None:
    """A stopped car revealed 20 to 32 m ahead at 13.9 m/s: a stop at d0 alone needs 4.1 to
    6.0 m/s^2, more than `room_decel`; the room is then what a stop at `room_decel_hard`
    leaves, so that the car stops where a pass path from a standstill clears the car (9 m
    back does, `test_passes_a_stopped_car_from_a_standstill_only_with_room_to_pull_out`) as
    far as that stop can; at d0 it would wait behind it for good."""
    p, acc = MotionLayerParams(overtake=True), AccParams()
    man = layer().update(ego(0.0, 100.0), V, [stopped_car(0.0, gap)])[0]
    hard = gap - 4.0 - V**2 / (2.0 * p.room_decel_hard)
    assert man.room_for == 7
    assert man.room == pytest.approx(min(max(hard, 0.0), 8.0), abs=0.05)
    if gap >= 27.0:
        assert acc.d0 + man.room >= 9.0


@pytest.mark.parametrize(("gap", "v", "room"), [
    (50.0, V, 50.0 - 4.0 - V**2 / 5.0),  # a gentle stop: at room_decel
    (60.0, V, 8.0),  # pass_gap - d0 at most
    (26.0, V, 26.0 - 4.0 - V**2 / 13.0),  # a stop at d0 needs 4.4 m/s^2: at room_decel_hard
    (10.0, V, 0.0),  # not even that stop leaves any
    (3.0, 0.0, 0.0),  # nearer than d0
    (9.0, 0.0, 5.0),  # standing: what lies beyond d0
])
def test_room_left(gap: float, v: float, room: float) -> None:
    assert room_left(gap, v, 4.0, MotionLayerParams()) == pytest.approx(room, abs=1e-9)


def test_a_flat_tyre_waits_for_the_car_behind_judged_at_the_speed_it_slows_to() -> None:
    """A flat tyre in lane 1, a car at 65 km/h 45 m behind in lane 0: at the car's speed
    now (59 km/h) lane 0 is free, but the car slows to a crawl while it moves over
    (`v_rear`): it waits in its lane."""
    m = MotionLayer(ROAD, 1, AccParams(), VEHICLE, MotionLayerParams())
    rear = car(0.0, 100.0 - 45.0 - 4.7, 0.0, 18.1, 9)
    fast_now = EgoState(t=0.0, x=100.0, y=W, heading=0.0, speed=16.4, yaw_rate=0.0,
                        steering_angle=0.0, position_sigma=0.05)
    assert m.update(fast_now, V, [rear], pull_over=True)[0].motion is \
        Motion.LANE_CHANGE_RIGHT
    m = MotionLayer(ROAD, 1, AccParams(), VEHICLE, MotionLayerParams())
    man = m.update(fast_now, V, [rear], pull_over=True, v_rear=6.4)[0]
    assert man.motion is Motion.LANE_KEEP


def test_keeping_right_yields_to_a_faster_car_behind_in_the_right_lane() -> None:
    """In lane 1 with nothing ahead, the car keeps right at once; not while a car at 90 km/h
    is 30 m behind in lane 0: it would have to brake at 5.3 m/s^2 (UN R157's rule, binding
    here: the `keep_right_gap` of 2 s, 27.8 m, alone would let it go)."""
    def first(tracks: list[Track]) -> Motion:
        m = MotionLayer(ROAD, 1, AccParams(), VEHICLE, MotionLayerParams(overtake=True))
        return m.update(ego(0.0, 100.0, W), V, tracks)[0].motion

    assert first([]) is Motion.LANE_CHANGE_RIGHT
    fast = car(0.0, 100.0 - VEHICLE.rear_overhang - 30.0 - 2.3, 0.0, 25.0, 3)
    assert first([fast]) is Motion.LANE_KEEP


def test_a_lane_counts_as_seen_behind_only_a_while_after_a_car_alongside_in_it() -> None:
    """Standing behind a stopped car, a car passes in the left lane at 60 km/h: it hides the
    lane behind it while alongside; the pass starts no sooner than `rear_view_time` (0.5
    s) after it was last alongside (at a standstill the gap ahead it needs is only 2 m)."""
    m = layer()
    last_alongside, start = -1.0, None
    for t in np.arange(0.0, 6.0, 0.025):
        passing = car(t, 100.0 - 40.0 + 16.7 * t, W, 16.7, 8)
        tracks = [stopped_car(t, 12.0), passing]
        if lane_traffic(ROAD, tracks, t, 100.0, (0, 1), m.params.occupancy,
                        VEHICLE)[1].alongside:
            last_alongside = t
        if m.update(standing(t, 100.0), V, tracks)[0].motion is Motion.LANE_CHANGE_LEFT:
            start = t
            break
    assert last_alongside > 0.0 and start is not None
    assert start - last_alongside == pytest.approx(0.5, abs=0.03)


def test_a_car_heading_off_its_lane_holds_it_on_a_flat_tyre() -> None:
    """A car turned ~164 deg off its lane (2.856 rad, as after a spin on a flat front tyre)
    has no lane-change path: the pull-over waits in the lane, no exception."""
    m = MotionLayer(ROAD, 1, AccParams(), VEHICLE, MotionLayerParams())
    spun = replace(ego(0.0, 100.0, W), heading=2.856, speed=0.0)
    for k in range(80):
        man, _ = m.update(replace(spun, t=0.025 * k), V, [], pull_over=True)
        assert man.motion is Motion.LANE_KEEP and man.lane == 1 and man.path is None
    # heading along the lane again, it pulls over
    man, _ = m.update(replace(spun, t=2.0, heading=0.0), V, [], pull_over=True)
    assert man.motion is Motion.LANE_CHANGE_RIGHT and man.lane == 0


VS = 5.56  # [m/s] 20 km/h: the ego and the slow car ahead it follows


def follow_slow(m: MotionLayer, t0: float, t1: float,
                fast: tuple[float, float] | None = None,
                ) -> list[tuple[float, Motion, int]]:
    """Step from t0 to t1 at 40 Hz with the ego at 20 km/h on the plan's path, wanting
    13.9 m/s, 25 m behind (centres) a car at its speed in lane 0; `fast` = (the ego's
    centre minus the car's at t0 [m], its speed [m/s]) of a car coming up in lane 1."""
    out, t, y = [], t0, 0.0
    while t < t1:
        x = 100.0 + VS * t
        tracks = [car(t, x + 25.0, 0.0, VS, 1)]
        if fast is not None:
            x_fast = 100.0 + VS * t0 - fast[0] + fast[1] * (t - t0)
            tracks.append(car(t, x_fast, W, fast[1], 2))
        man, _ = m.update(replace(ego(t, x, y), speed=VS), V, tracks)
        if man.path is not None:
            y = float(ROAD.lane(man.path.target_index).offset_at(x)) + float(
                man.path.offset_at(x))
        out.append((t, man.motion, man.lane))
        t += 0.025
    return out


def test_a_slow_ego_does_not_move_out_in_front_of_a_car_closing_fast() -> None:
    """At 20 km/h, a car at 65 km/h 37 m behind (bumpers) in the left lane: UN R157's rule
    holds (it would brake at 2.9 m/s^2), yet not braking it closes the gap in 3 s, before a
    change (~5 s) is over: the ego keeps its lane. Without that car it passes."""
    assert Motion.LANE_CHANGE_LEFT in {s[1] for s in follow_slow(layer(), 0.0, 2.0)}
    gap = 37.0 + VEHICLE.rear_overhang + 2.3  # [m] centre to centre, 37 m bumper to bumper
    steps = follow_slow(layer(), 0.0, 2.0, fast=(gap, 18.06))
    assert {s[1] for s in steps} == {Motion.LANE_KEEP}


def test_a_change_just_started_is_given_up_when_a_car_closing_fast_appears() -> None:
    """The pass has begun (not yet committed) when a car at 65 km/h is seen 35 m behind in
    the target lane: not braking it would reach the ego before its centre is in that lane;
    the change is aborted, back to lane 0."""
    m = layer()
    steps = follow_slow(m, 0.0, 2.0)
    start = next(s[0] for s in steps if s[1] is Motion.LANE_CHANGE_LEFT)
    assert m.motion is Motion.LANE_CHANGE_LEFT and 2.0 - start < 1.0
    gap = 35.0 + VEHICLE.rear_overhang + 2.3
    steps = follow_slow(m, 2.0, 2.2, fast=(gap, 18.06))
    assert steps[-1][1] is Motion.LANE_KEEP and steps[-1][2] == 0  # back to lane 0
    assert m.path is not None and m.path.target_index == 0


def test_after_passing_it_yields_at_once_to_a_faster_car_coming_up_behind() -> None:
    """A car at 75 km/h comes up in lane 1 30 m behind the ego, which has just passed a
    stopped car in lane 0: it keeps right as soon as the right lane is free by UN R157's
    rule (the stopped car 15 m behind: over 1 s at the ego's speed), without `keep_time`
    and without `keep_right_gap` at its own speed (27.8 m behind a car that stands): not
    lingering in the faster car's way."""
    m = MotionLayer(ROAD, 1, AccParams(), VEHICLE, MotionLayerParams(overtake=True))
    x0 = 100.0
    stopped = car(0.0, x0 - VEHICLE.rear_overhang - 15.0 - 2.3, 0.0, 0.0, 1)  # 15 m behind
    fast = car(0.0, x0 - VEHICLE.rear_overhang - 30.0 - 2.3, W, 20.8, 2)  # closing at 6.9 m/s
    man = m.update(ego(0.0, x0, W), V, [stopped, fast])[0]
    assert man.motion is Motion.LANE_CHANGE_RIGHT and man.lane == 0
    m = MotionLayer(ROAD, 1, AccParams(), VEHICLE, MotionLayerParams(overtake=True))
    assert m.update(ego(0.0, x0, W), V, [stopped])[0].motion is Motion.LANE_KEEP  # no
    #   faster car: the stopped car is under keep_right_gap behind at the ego's speed
    slow_behind = car(0.0, x0 - VEHICLE.rear_overhang - 30.0 - 2.3, W, V + 0.5, 2)
    m = MotionLayer(ROAD, 1, AccParams(), VEHICLE, MotionLayerParams(overtake=True))
    assert m.update(ego(0.0, x0, W), V, [stopped, slow_behind])[0].motion is \
        Motion.LANE_KEEP  # a car behind barely faster does not come up on it


def drive_heading(m: MotionLayer, t0: float, t1: float, slow_x0: float,
                  fast: tuple[float, float] | None = None) -> list[tuple[float, Motion, int]]:
    """`drive`, the ego heading along the plan's path too (its slope), as a car tracking it
    does: a path planned from the pose starts from that heading. It starts on the path in
    hand, if any."""
    out, t, x, y, heading = [], t0, 100.0 + V * t0, 0.0, 0.0
    if m.path is not None:
        y = float(ROAD.lane(m.path.target_index).offset_at(x)) + float(m.path.offset_at(x))
        heading = math.atan(float(m.path.slope_at(x)))
    while t < t1:
        tracks = [car(t, slow_x0 + 5.56 * t, 0.0, 5.56, 1)]
        if fast is not None:
            tracks.append(car(t, fast[0] + fast[1] * (t - t0), W, fast[1], 2))
        pose = EgoState(t=t, x=x, y=y, heading=heading, speed=V, yaw_rate=0.0,
                        steering_angle=0.0, position_sigma=0.05)
        man, _ = m.update(pose, V, tracks)
        t += 0.025
        x += V * 0.025
        if man.path is not None:
            y = float(ROAD.lane(man.path.target_index).offset_at(x)) + float(
                man.path.offset_at(x))
            heading = math.atan(float(man.path.slope_at(x)))
        out.append((t, man.motion, man.lane))
    return out


@pytest.mark.parametrize("t_abort", [2.2, 2.3])
def test_an_abort_before_the_body_reaches_the_line_keeps_it_off_the_line(
        t_abort: float) -> None:
    """A change to pass starts at 1.0 s; at `t_abort` a car at 30 m/s appears 45 m behind
    in the target lane (it would have to brake hard): the change is aborted while the
    body is still inside lane 0 but heading out. On the way back (perfect tracking) the
    body's side stays inside lane 0's left line: the way back is planned with
    ``abort_change`` (2 m/s^2), not the 0.85 m/s^2 of a planned change, whose path ran on
    0.40 and 0.44 m further out, the body 0.04 and 0.16 m over the line (now 0.17 and
    0.18 m, inside it)."""
    m = layer()
    steps = drive_heading(m, 0.0, t_abort, slow_x0=170.0)
    assert steps[-1][1] is Motion.LANE_CHANGE_LEFT and m.path is not None
    line = 0.5 * W - 0.075  # [m] the inner edge of the line between lanes 0 and 1
    half = 0.5 * VEHICLE.width  # [m] the body's half width
    x_now = 100.0 + V * t_abort
    y_now = float(m.path.offset_at(x_now)) + W  # lane 0's centre is the reference line
    assert y_now > 0.1 and y_now + half < line  # out of the lane's centre, not on the line
    assert float(m.path.slope_at(x_now)) > 0.02  # heading out
    drive_heading(m, t_abort, t_abort + 0.1, slow_x0=170.0, fast=(x_now - 45.0, 30.0))
    assert m.motion is Motion.LANE_KEEP and m.path is not None and m.path.target_index == 0
    y_back = m.path.offset_at(np.linspace(x_now, m.path.end, 400))
    assert y_back.max() + half < line


def test_the_room_granted_is_kept_when_the_stopped_car_gets_a_new_track() -> None:
    """As `test_the_room_granted_is_kept_through_a_gentler_stop`, but the tracker gives the
    stopped car a new track (id 9) after 0.3 s, 2 m nearer, whose first speed (0.1 s) wobbles
    to 0.8 m/s: the room granted to id 7 stays (it had fallen to 2.9 m in a campaign run,
    which then stood 7.2 m behind the car, where no pass path clears it, for good)."""
    m, t, x, v = layer(), 0.0, 100.0, V
    first = m.update(ego(0.0, x), V, [stopped_car(0.0, 50.0)])[0].room
    rooms = []
    while t < 0.9:
        t, x, v = t + 0.025, x + v * 0.025, v - 1.5 * 0.025
        track = stopped_car(t, 50.0)
        if t > 0.3:
            track = replace(track, id=9, x=track.x - 2.0, vx=0.8 if t < 0.4 else 0.0)
        man = m.update(replace(ego(t, x), speed=v), V, [track])[0]
        if man.room_for is not None:
            rooms.append(man.room)
    assert len(rooms) >= 30 and rooms == pytest.approx([first] * len(rooms))


def test_a_pass_waits_for_a_faster_car_it_would_not_outrun() -> None:
    """A car at 76 km/h 55 m behind (bumpers) in the left lane when the lane has been
    blocked for `blocked_time` (1 s), which never brakes: UN R157's rule for the move out
    holds (it would brake at 0.7 m/s^2) and it stays over 1 s behind until the move out
    (5 s) is over, but the pass of the 20 km/h car 63 m ahead (15 s, out, past and back) is
    not over before it comes up: the ego follows in lane 0. Behind a car at 45 km/h 15 m
    back in the left lane (the nearest, and not faster) the same: every vehicle behind
    counts. With that slower car alone, or the faster one 250 m back, it passes."""
    def bumper(gap: float) -> float:  # [m] the centre x at t = 0 of a car `gap` behind
        return 100.0 - VEHICLE.rear_overhang - gap - 2.3

    fast, slow = (bumper(55.0 + 76.0 / 3.6 - V), 76.0 / 3.6), (bumper(15.0), 45.0 / 3.6)
    occ = OccupancyParams()
    assert rear_decel_needed(55.0, fast[1], V, occ) < 1.0
    assert not rear_closes(55.0, fast[1], V, 5.0, occ)
    assert {s[1] for s in drive(layer(), 0.0, 3.0, 170.0, fast)} == {Motion.LANE_KEEP}
    both = drive_many(layer(), 0.0, 3.0, 170.0, (slow, fast))
    assert set(both) == {Motion.LANE_KEEP}
    assert Motion.LANE_CHANGE_LEFT in drive_many(layer(), 0.0, 3.0, 170.0, (slow,))
    far = (bumper(250.0), fast[1])
    assert Motion.LANE_CHANGE_LEFT in {s[1] for s in drive(layer(), 0.0, 3.0, 170.0, far)}


def drive_many(m: MotionLayer, t0: float, t1: float, slow_x0: float,
               left: tuple[tuple[float, float], ...]) -> list[Motion]:
    """`drive`'s motions with several cars in lane 1, each (x at t0, speed)."""
    out, t, x, y = [], t0, 100.0 + V * t0, 0.0
    while t < t1:
        tracks = [car(t, slow_x0 + 5.56 * t, 0.0, 5.56, 1)] + [
            car(t, x0 + v * (t - t0), W, v, 2 + k) for k, (x0, v) in enumerate(left)]
        man, _ = m.update(ego(t, x, y), V, tracks)
        if man.path is not None:
            y = float(ROAD.lane(man.path.target_index).offset_at(x)) + float(
                man.path.offset_at(x))
        out.append(man.motion)
        t += 0.025
        x += V * 0.025
    return out
