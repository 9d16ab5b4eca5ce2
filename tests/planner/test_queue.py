"""A car in a queue is not at its stop line (`planner.queue`): which tracks queue the car, and
the two rules that use it, the stop at a stop sign (`planner.events`) and the arrival at an
all-way stop (`planner.junctions`), with the car's estimate putting it at the line while it
queues behind the car that is there (a consumer receiver's error along the route; the
tracks are placed on the map in the same estimate, so the car ahead is placed past the line
by as much)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from perception.messages import ObjectClass, Track
from planner.events import EventMonitor, EventParams
from planner.fsm.acc import AccEvent
from planner.junctions import JunctionParams
from planner.queue import QueueParams, queued
from tests.planner.test_junctions import at_arm, at_stop, front_at, stop_monitor
from tests.roads import W, make_map, seg
from tests.vehicle import VEHICLE
from world.hdmap import RoadMap, StopSign

Q = QueueParams()
LINE = 200.0  # [m] the stop line's station
ROAD = make_map(seg(500.0), features=(StopSign(LINE),))  # a straight along +x, lane 0 on y = 0
LENGTH = 4.6  # [m] the tracks' length
CENTRE = 100.0  # [m] the car's centre station in the table
FRONT = CENTRE + VEHICLE.front_overhang


def vehicle(x: float, y: float = 0.0, vx: float = 0.0, vy: float = 0.0,
            cls: ObjectClass = ObjectClass.CAR) -> Track:
    return Track(id=1, t=0.0, x=x, y=y, vx=vx, vy=vy, rel_x=0.0, rel_y=0.0, rel_vx=0.0,
                 rel_vy=0.0, length=LENGTH, width=1.8, height=1.5, yaw=0.0, cls=cls, hits=9,
                 misses=0, position_sigma=0.1)


def rear_at(gap: float, y: float = 0.0, vx: float = 0.0, vy: float = 0.0) -> Track:
    """A car whose rear is `gap` [m] ahead of the table car's front bumper, `y` [m] left of
    lane 0's centre, moving at (vx, vy) [m/s]."""
    return vehicle(FRONT + gap + 0.5 * LENGTH, y, vx, vy)


@pytest.mark.parametrize(
    ("tracks", "expected"),
    [
        ((), False),
        ((rear_at(5.0),), True),  # standing 5 m ahead (the ACC's standstill gap)
        ((rear_at(Q.gap - 0.1),), True),
        ((rear_at(Q.gap + 0.1),), False),  # farther: the car is not queued behind it
        ((rear_at(5.0, vx=3.0),), True),  # moving off ahead: still queued until it is gone
        ((rear_at(5.0, y=W),), False),  # in the next lane
        ((rear_at(5.0, vy=5.0),), False),  # crossing in front (cross traffic in the box)
        ((vehicle(CENTRE - 8.0),), False),  # behind the car
        ((replace(rear_at(3.0), cls=ObjectClass.PEDESTRIAN),), False),  # not a vehicle
        ((replace(rear_at(3.0), cls=ObjectClass.TRUCK), rear_at(20.0)), True),
    ],
)
def test_which_tracks_queue_the_car(tracks: tuple[Track, ...], expected: bool) -> None:
    assert queued(ROAD, CENTRE, FRONT, 0.0, W, tracks) is expected


def _standing(m: EventMonitor, t: float, tracks: tuple[Track, ...]) -> bool:
    """Whether the stop sign still holds for the car standing with its front bumper 1.5 m
    before the line by its estimate, at time `t` [s]."""
    station = LINE - 1.5 - VEHICLE.front_overhang
    return m.update(t, station, 0.0, 0.0, W, tracks).holds(AccEvent.STOP_SIGN)


def test_a_stop_in_a_queue_is_not_the_stop_at_the_line_however_long() -> None:
    m = EventMonitor(ROAD, VEHICLE, EventParams())
    m.confirm_sign(LINE)
    ahead = (vehicle(LINE - 1.5 + 5.0 + 0.5 * LENGTH),)  # 5 m ahead: placed past the line
    for t in np.arange(0.0, 30.0, 0.5):  # queued 30 s: not done
        assert _standing(m, float(t), ahead), t
    # the car ahead has gone: the car now stands at the line itself, for stop_hold
    assert _standing(m, 30.0, ())
    assert _standing(m, 31.4, ())
    assert not _standing(m, 31.6, ())


def _lane0(road: RoadMap, s: float) -> tuple[float, float]:
    x, y = (float(a) for a in road.line.point(np.array(s), np.array(0.0)))
    return x, y


def test_an_all_way_stop_arrival_is_at_the_line_not_in_the_queue_before_it() -> None:
    """The car stands 1 m before its line by its estimate from t = 0, queued behind a car
    5 m ahead (placed in the box by the same estimate); a car on the left arm arrives at its
    line at t = 3 s; the car ahead leaves at t = 5 s and the car, now at its line, arrives
    then: after the car on the left, which goes first (first to stop, first to go)."""
    m = stop_monitor()
    p = JunctionParams()
    j = m.road.junctions[0]
    front = j.s_stop - 1.0
    x, y = _lane0(m.road, front + 5.0 + 0.5 * LENGTH)
    ahead = replace(at_arm("west", 8), x=x, y=y)
    left_coming, left_waiting = at_arm("north", 9, back=30.0, moving=5.0), at_arm("north", 9)
    for t in np.arange(0.0, 5.0, 0.5):
        at_stop(m, float(t), [ahead, left_waiting if t >= 3.0 else left_coming])
    assert m.update(5.0, front_at(m, 1.0), 0.0, [left_waiting]).holds(AccEvent.GIVE_WAY)
    assert at_stop(m, 5.0 + p.gap_confirm + 0.5, [left_waiting])  # it goes first
    assert at_stop(m, 7.0, [])  # it has gone: the car's turn, once clear for gap_confirm
    assert not at_stop(m, 7.0 + p.gap_confirm, [])
