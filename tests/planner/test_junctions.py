"""Town junction rules: lights as the camera saw them (the yellow rule, an unread light) and
giving way before a left turn or U-turn, on routes compiled from a grid town."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from perception.messages import LightDetection, ObjectClass, Track
from planner.fsm.acc import AccEvent
from planner.junctions import JunctionMonitor, JunctionParams
from tests.vehicle import VEHICLE
from world.hdmap import LightColour, Manoeuvre, RoadMap
from world.map.road import build_road_map
from world.map.town import TownLayout, compile_route
from world.spec import TownSpec

GIVE_WAY, RED_LIGHT = AccEvent.GIVE_WAY, AccEvent.RED_LIGHT

P = JunctionParams()
LIGHTS = TownLayout(TownSpec(3, 2, 90.0, 2, 3.5, 40 / 3.6, "traffic_lights"))
STOPS = TownLayout(TownSpec(3, 2, 90.0, 2, 3.5, 40 / 3.6, "stop_signs"))


def route(layout: TownLayout, manoeuvre: Manoeuvre) -> RoadMap:
    return build_road_map(compile_route(layout, (0, 1, "east"), (manoeuvre,), "ego"))


def car(x: float, y: float, vx: float = 0.0, vy: float = 0.0) -> Track:
    return Track(id=3, t=0.0, x=x, y=y, vx=vx, vy=vy, rel_x=0.0, rel_y=0.0, rel_vx=0.0,
                 rel_vy=0.0, length=4.6, width=1.8, height=1.5, yaw=0.0,
                 cls=ObjectClass.CAR, hits=9, misses=0, position_sigma=0.1)


def green(m: JunctionMonitor, t: float = 0.0) -> None:
    """Two green frames in a row: green confirmed."""
    m.see_lights([seen(LightColour.GREEN, t - 0.1)])
    m.see_lights([seen(LightColour.GREEN, t)])


def seen(colour: LightColour, t: float = 0.0) -> LightDetection:
    return LightDetection(t=t, light=0, colour=colour, range=30.0, confidence=0.9,
                          box=(0, 0, 1, 1))


def front_at(m: JunctionMonitor, before_line: float) -> float:
    """The car's centre station with its front bumper `before_line` [m] before the first
    junction's stop line."""
    return m.road.junctions[0].s_stop - before_line - VEHICLE.front_overhang


@pytest.mark.parametrize(
    ("colour", "before_line", "v", "stops"),
    [
        (LightColour.GREEN, 20.0, 11.0, False),
        (LightColour.RED, 20.0, 11.0, True),
        (LightColour.RED, 0.2, 0.0, True),  # standing at the line
        (LightColour.YELLOW, 40.0, 11.0, True),  # 11^2 / (2 x 39.5) = 1.5 m/s^2: stop
        (LightColour.YELLOW, 15.0, 11.0, False),  # 4.2 m/s^2 needed: go on
        (LightColour.YELLOW, 15.0, 8.0, True),  # 2.2 m/s^2: stop
        (None, 50.0, 11.0, False),  # unread, but far: no need to brake yet
        (None, 30.0, 11.0, False),  # 11^2 / 6 + 5 = 25.2 m: not yet
        (None, 25.0, 11.0, True),  # unread within braking distance at 3 m/s^2 + 5 m: stop
        (None, 45.0, 13.9, False),  # 50 km/h, 60 m is in the camera's range: read it first
    ],
)
def test_the_light_rules(colour: LightColour | None, before_line: float, v: float,
                         stops: bool) -> None:
    m = JunctionMonitor(route(LIGHTS, Manoeuvre.STRAIGHT), VEHICLE, P)
    if colour is not None:
        m.see_lights([seen(colour, -0.1)])
        m.see_lights([seen(colour)])
    e = m.update(0.5, front_at(m, before_line), v)
    assert e.holds(RED_LIGHT) is stops
    assert e.light is colour
    if stops:
        assert e.stop_distance == pytest.approx(before_line - P.stop_margin)


def test_a_yellow_decision_to_go_holds_when_it_turns_red() -> None:
    m = JunctionMonitor(route(LIGHTS, Manoeuvre.STRAIGHT), VEHICLE, P)
    m.see_lights([seen(LightColour.YELLOW, 0.0)])
    assert not m.update(0.0, front_at(m, 12.0), 11.0).holds(RED_LIGHT)
    m.see_lights([seen(LightColour.RED, 1.0)])
    assert not m.update(1.0, front_at(m, 2.0), 11.0).holds(RED_LIGHT)


def test_a_colour_seen_too_long_ago_is_not_trusted() -> None:
    m = JunctionMonitor(route(LIGHTS, Manoeuvre.STRAIGHT), VEHICLE, P)
    green(m, 0.0)
    # unread again: 8 m is within 5^2 / 6 + 5 = 9.2 m, where an unread light is stopped for
    assert m.update(P.light_memory + 0.5, front_at(m, 8.0), 5.0).holds(RED_LIGHT)


def test_the_light_over_the_line_is_no_longer_looked_at() -> None:
    m = JunctionMonitor(route(LIGHTS, Manoeuvre.STRAIGHT), VEHICLE, P)
    m.see_lights([seen(LightColour.RED)])
    assert not m.update(0.0, front_at(m, -0.5), 5.0).holds(RED_LIGHT)


def oncoming(m: JunctionMonitor, distance: float, speed: float) -> Track:
    """An oncoming car in the far arm's inner lane, `distance` past the junction's box."""
    j = m.road.junctions[0]
    hw = j.half_width
    return car(j.x + hw + distance, j.y + 1.75, vx=-speed)


@pytest.mark.parametrize(
    ("manoeuvre", "distance", "speed", "waits"),
    [
        (Manoeuvre.LEFT, 30.0, 10.0, True),  # 3 s away: wait
        (Manoeuvre.LEFT, 80.0, 10.0, False),  # 8 s away: go
        (Manoeuvre.LEFT, 30.0, 0.0, False),  # standing 30 m out: not coming
        (Manoeuvre.LEFT, 8.0, 0.0, True),  # standing at its own line: about to go
        (Manoeuvre.U_TURN, 30.0, 10.0, True),
        (Manoeuvre.RIGHT, 30.0, 10.0, False),  # turning right does not cross it
        (Manoeuvre.STRAIGHT, 30.0, 10.0, False),
    ],
)
def test_a_left_turn_waits_for_a_close_oncoming_car(manoeuvre: Manoeuvre, distance: float,
                                                    speed: float, waits: bool) -> None:
    m = JunctionMonitor(route(LIGHTS, manoeuvre), VEHICLE, P)
    green(m)
    e = m.update(0.0, front_at(m, 10.0), 6.0, [oncoming(m, distance, speed)])
    assert e.holds(GIVE_WAY) is waits
    assert not e.holds(RED_LIGHT)
    if waits:
        assert e.stop_distance == pytest.approx(10.0 - P.stop_margin)


def test_once_over_the_line_the_turn_is_committed() -> None:
    m = JunctionMonitor(route(LIGHTS, Manoeuvre.LEFT), VEHICLE, P)
    green(m)
    assert not m.update(0.0, front_at(m, -1.0), 3.0, [oncoming(m, 20.0, 10.0)]).holds(GIVE_WAY)


@pytest.mark.parametrize(
    ("before_line", "v", "gives_way"),
    [
        (10.0, 6.0, True),  # 6^2 / (2 x 9.5) = 1.9 m/s^2 <= 3: it can stop, so it waits
        (4.0, 6.0, False),  # 6^2 / (2 x 3.5) = 5.1 m/s^2 > 3: committed, it goes on
        (1.0, 3.5, False),  # rolling over the line (the far-car case): committed
        (0.5, 0.0, True),  # standing at the line: it waits
        (0.5, 0.4, True),  # creeping off the line, slower than `moving`: still waits
    ],
)
def test_giving_way_is_decided_while_the_car_can_still_stop(
    before_line: float, v: float, gives_way: bool,
) -> None:
    m = JunctionMonitor(route(LIGHTS, Manoeuvre.LEFT), VEHICLE, P)
    green(m)
    e = m.update(0.0, front_at(m, before_line), v, [oncoming(m, 30.0, 10.0)])
    assert e.holds(GIVE_WAY) is gives_way


def test_once_committed_a_closing_gap_does_not_stop_the_car() -> None:
    m = JunctionMonitor(route(LIGHTS, Manoeuvre.LEFT), VEHICLE, P)
    green(m)
    assert not m.update(0.0, front_at(m, 2.0), 5.0).holds(GIVE_WAY)  # no one coming; past its point
    assert not m.update(0.1, front_at(m, 1.5), 5.0, [oncoming(m, 30.0, 10.0)]).holds(GIVE_WAY)


def test_a_car_already_waiting_goes_on_waiting_however_close_to_the_line() -> None:
    """Hysteresis: braking for the gap, it reaches its stop point still moving; the
    commitment rule must not release it there."""
    m = JunctionMonitor(route(LIGHTS, Manoeuvre.LEFT), VEHICLE, P)
    green(m)
    car_coming = [oncoming(m, 30.0, 10.0)]
    assert m.update(0.0, front_at(m, 12.0), 6.0, car_coming).holds(GIVE_WAY)
    assert m.update(0.1, front_at(m, 1.0), 2.0, car_coming).holds(GIVE_WAY)


def standing_left_turn() -> JunctionMonitor:
    """A left turn at a green light, the car standing at its line."""
    m = JunctionMonitor(route(LIGHTS, Manoeuvre.LEFT), VEHICLE, P)
    green(m)
    return m


def at_line(m: JunctionMonitor, t: float, tracks: list[Track], v: float = 0.0,
            before_line: float = 1.0) -> bool:
    """Whether the car, `before_line` [m] before its line at `v` [m/s], gives way at t [s]."""
    return m.update(t, front_at(m, before_line), v, tracks).holds(GIVE_WAY)


def test_a_gap_is_taken_only_once_it_has_been_clear_for_gap_confirm() -> None:
    """The town_route case (issue K): the car that hid the next one goes by, the gap
    looks clear, and the next one's track comes 0.1 s later: the car has not taken the gap
    yet, so it waits on, once; the gap it takes is one clear for gap_confirm."""
    m = standing_left_turn()
    assert at_line(m, 0.0, [oncoming(m, 20.0, 10.0)])
    assert at_line(m, 2.0, [])  # clear since 2 s: not yet taken
    assert at_line(m, 2.1, [oncoming(m, 43.0, 9.6)])  # 4.5 s away: still waiting
    assert at_line(m, 2.2, [])  # clear again from 2.2 s
    assert at_line(m, 2.0 + P.gap_confirm, [])
    assert at_line(m, 2.19 + P.gap_confirm, [])
    assert not at_line(m, 2.2 + P.gap_confirm, [])  # taken


@pytest.mark.parametrize("v", [0.0, 0.4, 2.0])  # still standing, creeping off, moving
def test_a_taken_gap_is_not_given_up_when_an_oncoming_car_closes_it(v: float) -> None:
    m = standing_left_turn()
    assert at_line(m, 0.0, [oncoming(m, 20.0, 10.0)])
    assert at_line(m, 1.0, [])
    assert not at_line(m, 1.0 + P.gap_confirm, [])  # taken: committed
    late = [oncoming(m, 30.0, 10.0)]  # 3 s away: would have been waited for before
    assert not at_line(m, 1.1 + P.gap_confirm, late, v=v, before_line=0.9)
    assert not at_line(m, 1.5 + P.gap_confirm, late, v=v, before_line=0.5)


def test_a_taken_gap_is_given_up_for_a_vehicle_in_the_box_while_the_car_can_stop() -> None:
    """The safety reason: a vehicle stands (or crosses) in the box in the car's path."""
    m = standing_left_turn()
    j = m.road.junctions[0]
    in_box = [car(j.x + 1.0, j.y + 1.0, vx=0.0, vy=3.0)]
    assert at_line(m, 0.0, [oncoming(m, 20.0, 10.0)])
    assert at_line(m, 1.0, [])
    assert not at_line(m, 1.0 + P.gap_confirm, [])  # taken
    assert at_line(m, 1.7, in_box, v=1.0, before_line=0.9)  # 1 m/s: it can still stop
    # too fast to stop at commit_decel before its line: committed, the emergency stop's
    m = standing_left_turn()
    assert at_line(m, 0.0, [oncoming(m, 20.0, 10.0)])
    assert at_line(m, 1.0, [])
    assert not at_line(m, 1.0 + P.gap_confirm, [])
    assert not at_line(m, 1.7, in_box, v=3.0, before_line=0.9)


@pytest.mark.parametrize(
    ("vx", "vy", "waits"),
    [(0.0, 5.0, True), (0.0, 0.0, True), (5.0, 0.0, False)],  # across, standing, my way
)
def test_at_a_stop_sign_the_car_waits_for_the_box_to_clear(vx: float, vy: float,
                                                           waits: bool) -> None:
    m = JunctionMonitor(route(STOPS, Manoeuvre.STRAIGHT), VEHICLE, P)
    j = m.road.junctions[0]
    e = m.update(0.0, front_at(m, 1.0), 0.0, [car(j.x + 1.0, j.y - 2.0, vx, vy)])
    assert e.holds(GIVE_WAY) is waits
    # the box clear from t = 1 s: the gap is taken once it has been so for gap_confirm
    assert m.update(1.0, front_at(m, 1.0), 0.0, []).holds(GIVE_WAY) is waits
    assert m.update(0.99 + P.gap_confirm, front_at(m, 1.0), 0.0, []).holds(GIVE_WAY) is waits
    gone = m.update(1.0 + P.gap_confirm, front_at(m, 1.0), 0.0, [])
    assert not gone.holds(GIVE_WAY) and math.isinf(gone.stop_distance)


def test_an_unread_light_once_stopped_for_stays_so_until_read() -> None:
    m = JunctionMonitor(route(LIGHTS, Manoeuvre.STRAIGHT), VEHICLE, P)
    assert m.update(0.0, front_at(m, 25.0), 11.0).holds(RED_LIGHT)
    assert m.update(0.1, front_at(m, 24.0), 8.0).holds(RED_LIGHT)  # slower: still stopping for it
    green(m, 0.2)
    assert not m.update(0.2, front_at(m, 23.0), 8.0).holds(RED_LIGHT)


def test_a_red_light_missed_for_a_while_is_still_stopped_for() -> None:
    m = JunctionMonitor(route(LIGHTS, Manoeuvre.STRAIGHT), VEHICLE, P)
    m.see_lights([seen(LightColour.RED, 0.0)])
    assert m.update(0.0, front_at(m, 55.0), 11.0).holds(RED_LIGHT)
    assert m.update(3.0, front_at(m, 50.0), 10.0).holds(RED_LIGHT)  # not seen for 3 s, far away


def test_one_green_frame_does_not_let_the_car_go_through_a_red() -> None:
    m = JunctionMonitor(route(LIGHTS, Manoeuvre.STRAIGHT), VEHICLE, P)
    m.see_lights([seen(LightColour.RED, 0.0)])
    m.see_lights([seen(LightColour.GREEN, 0.1)])  # a false green in one frame
    assert m.update(0.15, front_at(m, 30.0), 8.0).holds(RED_LIGHT)
    m.see_lights([seen(LightColour.RED, 0.2)])
    m.see_lights([seen(LightColour.GREEN, 0.3)])
    m.see_lights([seen(LightColour.GREEN, 0.4)])  # it did turn green
    assert not m.update(0.45, front_at(m, 30.0), 8.0).holds(RED_LIGHT)


# ---- the all-way stop's order of arrival, from the tracks -----------------------------------

LINE_OUT = STOPS.mouth + 1.0  # [m] from a junction's centre to each stop line
LANE = STOPS.kerb_lane  # [m] lane 0's centre from the street's centre line


def at_arm(arm: str, track_id: int, back: float = 2.9, moving: float = 0.0) -> Track:
    """A car on `arm` of junction (1, 1) (`south`: coming from the south, heading north),
    in its inbound lane, its centre `back` [m] behind that arm's stop line, at speed
    `moving` [m/s] towards the junction."""
    cx, cy = STOPS.centre((1, 1))
    out = {"south": (0.0, -1.0), "north": (0.0, 1.0), "east": (1.0, 0.0),
           "west": (-1.0, 0.0)}[arm]
    right = (-out[1], out[0])  # right of the inbound direction (-out)
    d = LINE_OUT + back
    x, y = cx + d * out[0] + LANE * right[0], cy + d * out[1] + LANE * right[1]
    return replace(car(x, y, -moving * out[0], -moving * out[1]), id=track_id)


def at_stop(m: JunctionMonitor, t: float, tracks: list[Track]) -> bool:
    """Whether the car, standing at its line at time t, gives way."""
    return m.update(t, front_at(m, 1.0), 0.0, tracks).holds(GIVE_WAY)


def stop_monitor() -> JunctionMonitor:
    return JunctionMonitor(route(STOPS, Manoeuvre.STRAIGHT), VEHICLE, P)


# (arm, seen there from [s], the car stands at its line from t = 2 s: waits for it)
ARRIVAL_TABLE = [
    ("south", 0.0, True),  # first seen waiting there: there before the car
    ("north", 0.0, True),  # on the left, but earlier: first to stop, first to go
    ("east", 0.0, True),  # oncoming, earlier
    ("south", 2.5, True),  # a tie, on the car's right: it goes first
    ("north", 2.5, False),  # a tie, on the car's left: the car goes first
    ("east", 2.5, False),  # a tie, oncoming: nobody on the car's right, it goes first
    ("south", 3.5, False),  # after the car: the car goes first
]


@pytest.mark.parametrize(("arm", "since", "waits"), ARRIVAL_TABLE)
def test_an_all_way_stop_goes_in_order_of_arrival(arm: str, since: float, waits: bool) -> None:
    m = stop_monitor()
    approaching = at_arm(arm, 7, back=30.0, moving=5.0)
    waiting = at_arm(arm, 7)
    for t in (0.0, 0.5, 1.0, 1.5):
        m.update(t, front_at(m, 1.0 + (2.0 - t)), 1.0, [waiting if since <= t else approaching])
    for t in (2.0, 2.5, 3.0, 3.5, 4.0, 6.0):
        tracks = [waiting if since <= t else approaching]
        at_stop(m, t, tracks)
    assert at_stop(m, 6.5, [waiting]) is waits
    # it has gone into the junction: the car's turn, once that has held for gap_confirm
    assert at_stop(m, 7.0, []) is waits
    assert not at_stop(m, 7.0 + P.gap_confirm, [])


def test_a_car_queued_on_another_arm_or_behind_the_car_is_not_waited_for() -> None:
    m = stop_monitor()
    queued = at_arm("south", 4, back=2.9 + 4.8 + 3.0)  # behind the first of its queue
    behind = at_arm("west", 5, back=2.9 + 4.8 + 3.0)  # behind the car, on its own arm
    assert not at_stop(m, 0.0, [queued, behind])
    assert not at_stop(m, 3.0, [queued, behind])


def test_a_car_that_moves_off_its_line_is_waited_for_until_it_has_crossed() -> None:
    """town_traffic's contact at 456 s (issue K): the car first to stop moves off its line;
    it no longer waits there, but it is taking its turn: the car waits while it is on its
    way in and across, and goes once it has left (after gap_confirm)."""
    m = stop_monitor()
    assert at_stop(m, 0.0, [at_arm("south", 4)])
    on_its_way = [at_arm("south", 4, back=-3.0, moving=3.0)]  # 3 m past its line
    assert at_stop(m, 1.0, on_its_way)
    assert at_stop(m, 1.0 + P.gap_confirm, on_its_way)  # on its way in: still its turn
    cx, cy = STOPS.centre((1, 1))
    across = [replace(car(cx + LANE, cy, 0.0, 3.0), id=4)]  # in the box, heading north
    assert at_stop(m, 2.0, across)
    gone = [replace(car(cx + LANE, cy + LINE_OUT + 3.0, 0.0, 3.0), id=4)]  # left it
    assert at_stop(m, 3.0, gone)  # the gap not yet taken (gap_confirm)
    assert not at_stop(m, 3.0 + P.gap_confirm, gone)


def test_a_car_leaving_the_junction_on_the_cars_own_arm_is_not_waited_for() -> None:
    """Past the car's stop line but moving away from the centre: no conflict."""
    m = stop_monitor()
    cx, cy = STOPS.centre((1, 1))
    leaving = [replace(car(cx - LINE_OUT + 2.0, cy + LANE, -5.0, 0.0), id=6)]  # westbound
    assert not at_stop(m, 0.0, leaving)


def test_a_gap_taken_queued_behind_another_car_is_judged_again_at_the_line() -> None:
    """town_traffic's contact at 561 s (issue K): second in the queue for a left turn, the
    car took a gap 15 m before its line and, committed, turned 5 s later, behind the car
    ahead, into a car that had come near since. A gap taken away from the line does not
    commit: an oncoming car that comes within gap_time on the way up is waited for."""
    m = standing_left_turn()
    assert at_line(m, 0.0, [oncoming(m, 20.0, 10.0)], before_line=15.0)
    assert at_line(m, 1.0, [], before_line=15.0)
    assert not at_line(m, 1.0 + P.gap_confirm, [], before_line=15.0)  # taken, not committed
    assert not at_line(m, 2.0, [oncoming(m, 90.0, 10.0)], v=2.0, before_line=10.0)
    assert at_line(m, 3.0, [oncoming(m, 40.0, 10.0)], v=2.0, before_line=8.0)  # 4 s away


def test_at_an_all_way_stop_the_car_does_not_commit_before_it_has_stood() -> None:
    """Too fast to stop at commit_decel 10 m before the line (where the stop sign's own
    event brakes it anyway): still not committed, so its turn is judged once it stands."""
    m = stop_monitor()
    assert m.update(0.0, front_at(m, 10.0), 9.0, []).active == frozenset()
    assert at_stop(m, 3.0, [at_arm("south", 4)])  # it stood: the earlier car goes first


@pytest.mark.parametrize(("vx", "vy", "gives_way"), [
    (-3.5, -3.5, True),  # an oncoming car half way through its left turn, across the lane
    (-5.0, 0.0, False),  # an oncoming car going straight through, in its own lane
])
def test_going_straight_on_green_the_car_waits_for_a_car_turning_across(
        vx: float, vy: float, gives_way: bool) -> None:
    """Straight on, with right of way at a green light, the car at its line does not enter
    while a vehicle in the box moves across its path (`planner.crossing`)."""
    m = JunctionMonitor(route(LIGHTS, Manoeuvre.STRAIGHT), VEHICLE, P)
    green(m)
    j = m.road.junctions[0]
    turning = car(j.x + 1.0, j.y + 1.75, vx, vy)
    out = m.update(0.0, front_at(m, 0.6), 0.0, [turning])
    assert out.holds(GIVE_WAY) is gives_way
    assert not m.update(0.1, front_at(m, 0.6), 0.0, []).holds(GIVE_WAY)


@pytest.mark.parametrize(
    ("back", "speed", "waits"),
    [
        (2.9, 0.0, False),  # stands at its line, arrived after the car: the car's turn
        (20.0, 8.0, False),  # 2.8 s from the box, but it can stop at its line (1.8 m/s^2)
        (3.0, 8.0, True),  # 3.6 m from its line at 8 m/s (8.9 m/s^2): it will not stop
        (-3.0, 3.0, True),  # over its line, coming in: the box's rule
    ],
)
def test_a_left_turn_at_an_all_way_stop_waits_only_for_an_oncoming_car_that_will_not_stop(
        back: float, speed: float, waits: bool) -> None:
    """town_0020's wait of 20 s: the car stood first at its line to turn left; the
    oncoming car came and stood at its own line after it, waiting for the car's turn, and
    the car waited for it as for a gap (standing near the box). At an all-way stop an
    oncoming car that stops at its line takes its turn in the order of arrival."""
    m = JunctionMonitor(route(STOPS, Manoeuvre.LEFT), VEHICLE, P)
    assert not at_stop(m, 0.0, [])  # the car stands at its line from 0 s: it arrived
    far = at_arm("east", 7, back=60.0, moving=8.0)  # 7.9 s from the box: not soon
    assert not at_stop(m, 2.0, [far])
    there = at_arm("east", 7, back=back, moving=speed)
    assert at_stop(m, 3.0, [there]) is waits
    assert at_stop(m, 3.0 + P.gap_confirm, [there]) is waits


def test_a_left_turn_at_an_all_way_stop_waits_for_an_oncoming_car_that_stood_first() -> None:
    m = JunctionMonitor(route(STOPS, Manoeuvre.LEFT), VEHICLE, P)
    m.update(0.0, front_at(m, 20.0), 5.0, [at_arm("east", 7, back=30.0, moving=5.0)])
    first = at_arm("east", 7)
    m.update(1.0, front_at(m, 6.0), 2.0, [first])  # stands at its line before the car
    assert at_stop(m, 3.0, [first])  # the car stands 2 s after it: it goes first
    assert at_stop(m, 5.0, [first])
    assert at_stop(m, 6.0, [])  # it has gone: the car's turn, once the gap is confirmed
    assert not at_stop(m, 6.0 + P.gap_confirm, [])
