"""Town drivers (`world.actors.town_traffic`): the vehicles too far to be followed are not
looked at, and that changes no speed cap; the vehicle ahead is followed, one behind never;
an all-way stop is taken in order of arrival, a queued car makes its own stop at the line;
the left turn on green waits for oncoming traffic; at its route's end an NPC leaves."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from avsim.scenario.load import load_scenario
from world.actors import town_traffic
from world.actors.all_way_stop import AllWayStop
from world.actors.town_traffic import FOLLOW_LANE_HALF, LOOK_AHEAD, Others, TownDriver
from world.hdmap import LightColour, Manoeuvre
from world.map.road import build_road_map
from world.map.signals import light_colour, route_signals
from world.map.town import TownLayout, compile_route
from world.spec import TownSpec
from world.world import World


@pytest.fixture(scope="module")
def drivers() -> Iterator[list[TownDriver]]:
    world = World(load_scenario("town_route").world)  # its NPCs drive their own town routes
    try:
        found = [d for d in world.actors._drivers if d is not None]
        assert found
        yield found
    finally:
        world.close()


def others_near(driver: TownDriver, s: float, data: st.DataObject) -> np.ndarray:
    """Vehicle centres around the route at s: some on the route ahead or behind (within or
    beyond LOOK_AHEAD, on or off the lane), some anywhere in a 300 m square."""
    line = driver.road.line
    points = []
    for _ in range(data.draw(st.integers(0, 6))):
        if data.draw(st.booleans()):
            along = data.draw(st.floats(-2.0 * LOOK_AHEAD, 2.0 * LOOK_AHEAD))
            offset = data.draw(st.floats(-3.0 * FOLLOW_LANE_HALF, 3.0 * FOLLOW_LANE_HALF))
            station = min(max(s + along, 0.0), driver.road.length)
            x, y, _ = line.pose_one(station, offset)
        else:
            cx, cy, _ = line.pose_one(s, 0.0)
            x = cx + data.draw(st.floats(-150.0, 150.0))
            y = cy + data.draw(st.floats(-150.0, 150.0))
        points.append((x, y))
    return np.array(points, dtype=np.float64).reshape(-1, 2)


@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_the_reach_filter_changes_no_cap(drivers: list[TownDriver], data: st.DataObject,
                                         ) -> None:
    driver = data.draw(st.sampled_from(drivers))
    s = data.draw(st.floats(0.0, driver.road.length))
    speed = data.draw(st.floats(0.0, 15.0))
    others = others_near(driver, s, data)
    seen = still(others)
    filtered = driver._follow_cap(s, speed, seen)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(town_traffic, "FOLLOW_REACH", math.inf)  # look at every vehicle
        everything = driver._follow_cap(s, speed, seen)
    assert filtered == everything


def test_a_vehicle_ahead_on_the_lane_caps_the_speed(drivers: list[TownDriver]) -> None:
    """The property above is not empty: a vehicle 20 m ahead on the lane is followed, and
    one 200 m to the side is not."""
    driver = drivers[0]
    s = 0.3 * driver.road.length
    ahead = np.array([driver.road.line.pose_one(s + 20.0, 0.0)[:2]])
    aside = ahead + np.array([[0.0, 200.0]])
    behind = np.array([driver.road.line.pose_one(s - 8.0, 0.0)[:2]])
    assert driver._follow_cap(s, 10.0, still(ahead)) < 10.0
    assert driver._follow_cap(s, 10.0, still(aside)) == math.inf
    assert driver._follow_cap(s, 10.0, still(behind)) == math.inf  # never one behind


def still(xy: np.ndarray) -> Others:
    """Standing sedans at `xy` (N, 2) [m]."""
    return Others(xy, np.zeros_like(xy), np.full(len(xy), 2.4))


# ---- the rules at a junction, on a small town of one lane each way -------------------------

HALF = 2.4  # [m] a sedan's centre to its bumper


def town(junctions: str) -> TownLayout:
    return TownLayout(TownSpec(blocks_x=2, blocks_y=2, block=80.0, lanes=1, lane_width=3.5,
                               speed_limit=11.0, junctions=junctions))


def driver(layout: TownLayout, start: tuple[int, int, str], route: list[Manoeuvre], key: str,
           order: AllWayStop) -> TownDriver:
    spec = compile_route(layout, start, route, key)
    road = build_road_map(spec)
    return TownDriver(road, route_signals(spec, road), HALF, key, order)


def at_line(d: TownDriver) -> float:
    """[m] the station of its centre standing at its first junction's line."""
    return d.road.junctions[0].s_stop - town_traffic.STOP_MARGIN - HALF


def centre(d: TownDriver, s: float) -> np.ndarray:
    return np.array([d.road.line.pose_one(s, 0.0)[:2]])


def test_an_all_way_stop_goes_in_order_of_arrival() -> None:
    """Two cars stop at the all-way stop (1, 1), from the west and from the south: the
    first to stop goes first; the second waits until the first is over its line and out
    of the box."""
    order = AllWayStop()
    layout = town("stop_signs")
    west = driver(layout, (0, 1, "east"), [Manoeuvre.STRAIGHT], "west", order)
    south = driver(layout, (1, 0, "north"), [Manoeuvre.STRAIGHT], "south", order)
    sw, ss = at_line(west), at_line(south)
    nobody = town_traffic.no_others()
    assert west.speed_cap(0.0, sw, 0.0, nobody) == 0.0  # arrives at t = 0
    assert south.speed_cap(2.0, ss, 0.0, nobody) == 0.0  # arrives at t = 2
    t = 2.0 + town_traffic.STOP_DWELL + 0.1
    assert west.speed_cap(t, sw, 0.0, still(centre(south, ss))) > 0.0  # first: goes
    assert south.speed_cap(t, ss, 0.0, still(centre(west, sw))) == 0.0  # waits its turn
    # west is over its line, in the box: south still waits (the box is not clear)
    in_box = west.road.junctions[0].s_enter + 8.0
    west.speed_cap(t + 3.0, in_box, 3.0, nobody)
    assert south.speed_cap(t + 3.0, ss, 0.0, still(centre(west, in_box))) == 0.0
    # west has gone through: south's turn
    assert south.speed_cap(t + 6.0, ss, 0.0, still(centre(west, in_box + 40.0))) > 0.0


@pytest.mark.parametrize(("over_line", "speed", "waits"), [
    (1.0, 2.0, True),  # its front 1 m over its line, moving in: taking its turn
    (-1.0, 1.0, True),  # pulling off its line (the ego leaves the order at STOP_SPEED)
    (-1.0, 0.0, False),  # standing there: not coming (it waits its own turn)
    (1.0, -2.0, False),  # backing away from the box
])
def test_an_npc_waits_for_a_car_on_its_way_into_the_box(over_line: float, speed: float,
                                                         waits: bool) -> None:
    """town_0020: the car first to stop moved off its line and left the order; the next
    NPC got the turn and went while that car, not yet in the box, was driving into it."""
    order = AllWayStop()
    layout = town("stop_signs")
    west = driver(layout, (0, 1, "east"), [Manoeuvre.STRAIGHT], "west", order)
    south = driver(layout, (1, 0, "north"), [Manoeuvre.STRAIGHT], "south", order)
    ss = at_line(south)
    nobody = town_traffic.no_others()
    assert south.speed_cap(0.0, ss, 0.0, nobody) == 0.0  # arrives: the only one, its turn
    s = west.road.junctions[0].s_stop - HALF + over_line  # [m] west's centre
    j = south.road.junctions[0]
    xy = centre(west, s)
    assert abs(xy[0, 0] - j.x) > j.half_width  # not in the box
    coming = Others(xy, np.array([[speed, 0.0]]), np.full(1, HALF))  # eastbound
    t = town_traffic.STOP_DWELL + 0.1
    assert (south.speed_cap(t, ss, 0.0, coming) == 0.0) is waits
    assert south.speed_cap(t + 0.1, ss, 0.0, nobody) > 0.0


def test_a_queued_car_moves_up_and_stops_at_the_line_itself() -> None:
    """A car queued behind one at the line is held by it, not by the line; when it leaves,
    it moves up, and must stand at the line for its own stop before it may go."""
    order = AllWayStop()
    layout = town("stop_signs")
    first = driver(layout, (0, 1, "east"), [Manoeuvre.STRAIGHT], "first", order)
    second = driver(layout, (0, 1, "east"), [Manoeuvre.STRAIGHT], "second", order)
    s1 = at_line(first)
    s2 = s1 - 2.0 * HALF - town_traffic.FOLLOW_GAP + 0.5  # queued, inside the standstill gap
    nobody = town_traffic.no_others()
    assert first.speed_cap(0.0, s1, 0.0, nobody) == 0.0
    assert second.speed_cap(0.0, s2, 0.0, still(centre(first, s1))) == 0.0
    assert order.arrived_at((1, 1), "second") is None  # queued: it has not arrived
    assert first.speed_cap(2.0, s1, 0.0, nobody) > 0.0  # first goes
    first.speed_cap(4.0, s1 + 10.0, 3.0, nobody)  # over its line
    assert second.speed_cap(4.0, s2, 0.0, still(centre(first, s1 + 10.0))) > 0.0  # moves up
    assert second.speed_cap(8.0, s1, 0.0, nobody) == 0.0  # its own stop at the line
    assert second.speed_cap(8.0 + town_traffic.STOP_DWELL + 0.1, s1, 0.0, nobody) > 0.0


def test_an_npc_does_not_wait_for_a_car_behind_it_or_queued() -> None:
    """At the line, with cars behind it in its own queue and one queued on the cross street
    (none of them arrived), it goes after its dwell."""
    order = AllWayStop()
    layout = town("stop_signs")
    d = driver(layout, (0, 1, "east"), [Manoeuvre.STRAIGHT], "npc", order)
    cross = driver(layout, (1, 0, "north"), [Manoeuvre.STRAIGHT], "cross", order)
    s = at_line(d)
    behind = np.vstack([centre(d, s - 9.0), centre(cross, at_line(cross) - 9.0)])
    d.speed_cap(0.0, s, 0.0, still(behind))
    assert d.speed_cap(town_traffic.STOP_DWELL + 0.1, s, 0.0, still(behind)) > 0.0


@pytest.mark.parametrize(("oncoming_at", "speed", "across", "waits"), [
    (30.0, 8.0, False, True),  # coming, 30 m beyond the box at 8 m/s: there within the gap
    (120.0, 8.0, False, False),  # too far to count
    (HALF + 1.0, 0.0, False, True),  # standing at its line: goes on the same green, first
    (15.0, 0.0, False, True),  # queued behind the line: pulls away into the box in time
    (15.0, 1.0, False, True),  # creeping up the queue: the pull-away, not its speed, counts
    (40.0, 0.0, False, False),  # standing farther back: out of the gap from rest
    (HALF + 1.0, 0.0, True, False),  # standing to turn left itself: the turns pass
    (30.0, 8.0, True, True),  # coming at speed, whatever it means to do
    (-1.0, 5.0, False, True),  # in the box, coming this way
])
def test_a_left_turn_on_green_waits_for_oncoming_traffic(oncoming_at: float, speed: float,
                                                        across: bool, waits: bool) -> None:
    layout = town("traffic_lights")
    d = driver(layout, (0, 1, "east"), [Manoeuvre.LEFT], "npc", AllWayStop())
    j = d.road.junctions[0]
    plan = d._lines[0].light
    assert plan is not None
    green = next(t for t in np.arange(0.0, 40.0, 0.5)
                 if light_colour(plan, t) is LightColour.GREEN)
    # the oncoming lane: left of the approach's axis, heading west towards the box
    x = j.x + j.half_width + oncoming_at if oncoming_at >= 0.0 else j.x + 1.0
    y = j.y + 1.75
    others = Others(np.array([[x, y]]), np.array([[-speed, 0.0]]), np.array([HALF]),
                    np.array([across]))
    cap = d.speed_cap(float(green), at_line(d), 0.0, others)
    assert (cap == 0.0) is waits


def test_which_npcs_turn_across_next() -> None:
    """A driver knows its own next turn, and it is no longer the one behind it."""
    layout = town("traffic_lights")
    left = driver(layout, (0, 1, "east"), [Manoeuvre.LEFT], "left", AllWayStop())
    ahead = driver(layout, (0, 1, "east"), [Manoeuvre.STRAIGHT], "ahead", AllWayStop())
    assert left.turns_across_next() and not ahead.turns_across_next()
    left.speed_cap(0.0, left.road.junctions[0].s_exit, 5.0, town_traffic.no_others())
    assert not left.turns_across_next()


def test_at_its_route_end_an_npc_arrives() -> None:
    d = driver(town("stop_signs"), (0, 1, "east"), [Manoeuvre.STRAIGHT], "npc", AllWayStop())
    end = d.road.length - HALF - 0.5
    d.speed_cap(0.0, end - 20.0, 5.0, town_traffic.no_others())
    assert not d.arrived
    d.speed_cap(1.0, end, 0.0, town_traffic.no_others())
    assert d.arrived


@pytest.mark.parametrize(("back", "speed", "stopped", "at"), [
    (0.0, 0.0, town_traffic.EGO_STOPPED, True),  # standing at its line
    (3.0, 0.05, town_traffic.EGO_STOPPED, True),  # within the zone
    (0.0, 0.2, town_traffic.EGO_STOPPED, False),  # still rolling: not arrived yet ...
    (0.0, 0.2, town_traffic.STOP_SPEED, True),  # ... but once arrived, not left either
    (9.0, 0.0, town_traffic.EGO_STOPPED, False),  # queued behind a car at the line
])
def test_where_the_ego_stands_at_an_all_way_stop(back: float, speed: float, stopped: float,
                                                 at: bool) -> None:
    layout = town("stop_signs")
    road = build_road_map(compile_route(layout, (0, 1, "east"), [Manoeuvre.STRAIGHT], "ego"))
    zones = town_traffic.StopZones(road)
    j = road.junctions[0]
    x, y, _ = road.line.pose_one(j.s_stop - 0.5 - HALF - back, 0.0)
    found = zones.at_line((x, y), HALF, speed, stopped)
    assert (found is not None and found.index == (1, 1)) is at
