"""Vehicles crossing the car's path at a town junction (`planner.crossing`), on synthetic
tracks at the junction (1, 1) of a small town, the car going straight east through it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planner.crossing import CrossingParams, TurnRates, conflict_station, crossing_stop
from world.hdmap import Manoeuvre, RoadMap
from world.map.road import build_road_map
from world.map.town import TownLayout, compile_route
from world.spec import TownSpec

P = CrossingParams()


def road(manoeuvre: Manoeuvre = Manoeuvre.STRAIGHT) -> RoadMap:
    layout = TownLayout(TownSpec(blocks_x=2, blocks_y=2, block=80.0, lanes=1, lane_width=3.5,
                                 speed_limit=11.0, junctions="traffic_lights"))
    return build_road_map(compile_route(layout, (0, 1, "east"), [manoeuvre], "ego"))


def one(x: float, y: float, vx: float, vy: float) -> tuple[np.ndarray, np.ndarray]:
    return np.array([[x, y]]), np.array([[vx, vy]])


def at_line(r: RoadMap) -> float:
    """[m] the front bumper's station standing at the first junction's line."""
    return r.junctions[0].s_stop - 0.5


def lane_y(r: RoadMap) -> float:
    """[m] y of the car's lane centre through the junction (eastbound)."""
    j = r.junctions[0]
    return float(r.line.pose_one(j.s_stop, float(r.lanes[0].offset_at(j.s_stop)))[1])


def test_an_oncoming_car_turning_left_in_the_box_stops_the_car_at_its_line() -> None:
    """The case of the town run: the car stands at its line on green; an oncoming car is
    in the box, half way through its left turn (heading south-west), across the car's
    lane ahead within the horizon: the car stays at its line."""
    r = road()
    j = r.junctions[0]
    front = at_line(r)
    h = math.radians(225.0)  # west-bound turning south: half way through its left turn
    xy, vel = one(j.x + 1.0, j.y + 1.0, 5.0 * math.cos(h), 5.0 * math.sin(h))
    assert conflict_station(r, j, front, 0.0, xy, vel, P, float(r.lanes[0].offset_at(front)))
    stop = crossing_stop(r, j, front, 0.0, xy, vel, P, float(r.lanes[0].offset_at(front)))
    assert stop is not None and stop == pytest.approx(j.s_stop - front)


def test_moving_fast_past_where_it_can_stop_at_its_line_it_stops_short_of_the_conflict(
) -> None:
    r = road()
    j = r.junctions[0]
    front = j.s_stop - 3.0  # 3 m before the line at 9.5 m/s: not stoppable at A_FIRM there
    off = float(r.lanes[0].offset_at(front))
    xy, vel = one(j.x - 1.0, lane_y(r) + 4.0, 0.0, -5.0)  # crossing southwards, in the box
    s = conflict_station(r, j, front, 9.5, xy, vel, P, off)
    stop = crossing_stop(r, j, front, 9.5, xy, vel, P, off)
    assert s is not None and stop is not None
    assert stop == pytest.approx(s - front - P.standoff)
    assert stop > j.s_stop - front  # beyond the line, short of the conflict


@pytest.mark.parametrize(("x", "dy", "vx", "vy", "why"), [
    (-30.0, 0.0, 8.0, 0.0, "ahead, going the car's way"),
    (10.0, 3.5, -8.0, 0.0, "oncoming, in its own lane"),
    (1.0, 3.5, -8.0, -1.0, "oncoming, drifting a few degrees"),
    (-1.0, 6.0, 0.0, -0.2, "standing at the cross street's line"),
    (-1.0, 40.0, 0.0, -8.0, "crossing, but far from the box"),
    (-1.0, -6.0, 0.0, -8.0, "crossed, driving away"),
])
def test_what_is_not_a_conflict(x: float, dy: float, vx: float, vy: float, why: str) -> None:
    r = road()
    j = r.junctions[0]
    front = at_line(r)
    xy, vel = one(j.x + x, lane_y(r) + dy, vx, vy)
    assert conflict_station(r, j, front, 0.0, xy, vel, P,
                            float(r.lanes[0].offset_at(front))) is None, why


def test_a_car_that_has_gone_by_before_the_car_gets_there_is_not_waited_for() -> None:
    """A crossing car 1 m short of the car's lane at 10 m/s has gone by in well under a
    second: the car, 40 m back at 5 m/s, cannot meet it; standing at the line it would."""
    r = road()
    j = r.junctions[0]
    xy, vel = one(j.x, lane_y(r) + 3.0, 0.0, -10.0)
    back = j.s_stop - 40.0
    assert conflict_station(r, j, back, 5.0, xy, vel, P,
                            float(r.lanes[0].offset_at(back))) is None
    front = at_line(r)
    assert conflict_station(r, j, front, 8.0, xy, vel, P,
                            float(r.lanes[0].offset_at(front))) is not None


def test_the_path_is_the_cars_own_turn() -> None:
    """Turning left, a car coming into the box from the south (northbound, on the car's
    right) slowly, crosses its path as the car turns into its street."""
    r = road(Manoeuvre.LEFT)
    j = r.junctions[0]
    front = at_line(r)
    xy, vel = one(j.x + 1.75, j.y - 9.0, 0.0, 3.0)
    s = conflict_station(r, j, front, 0.0, xy, vel, P, float(r.lanes[0].offset_at(front)))
    assert s is not None and j.s_enter < s < j.s_exit


def test_a_car_starting_its_left_turn_is_predicted_by_its_turn_rate() -> None:
    """An oncoming car just into the box, still heading almost west but turning left at
    0.6 rad/s: straight ahead it passes in its own lane, along its turn it crosses the
    car's lane; the turn rate comes from two looks at its velocity (`TurnRates`)."""
    r = road()
    j = r.junctions[0]
    front = at_line(r)
    off = float(r.lanes[0].offset_at(front))
    h = math.radians(185.0)
    xy, vel = one(j.x + 3.0, j.y + 1.75, 6.0 * math.cos(h), 6.0 * math.sin(h))
    assert conflict_station(r, j, front, 0.0, xy, vel, P, off) is None
    rates = TurnRates(P.moving)
    before = h - 0.06  # [rad] 0.1 s earlier
    rates.update([0.0], [7], np.array([[6.0 * math.cos(before), 6.0 * math.sin(before)]]))
    rate = rates.update([0.1], [7], vel)
    assert rate[0] == pytest.approx(0.6)
    assert rates.update([0.1], [7], vel)[0] == pytest.approx(0.6)  # the same state again
    assert conflict_station(r, j, front, 0.0, xy, vel, P, off, rate) is not None
