"""A car in a queue is not at its stop line: whether a vehicle stands (or moves off) right in
front of the car, in the lane it keeps.

A stop at a stop line counts, and an arrival at an all-way stop begins, only where the car
stands at the line itself (`planner.events`, `planner.junctions`). Its front bumper within a
few metres of the line by its own estimate is not enough: with a consumer GNSS receiver the
station along the route may be off by metres, and the car ahead, standing at the line,
hides the paint the camera would place the car by (`perception.stop_lines`). Nor can the
map's line tell a vehicle between the car and the line from one beyond it: the tracks are
placed on the map in the car's own pose estimate, so they are off along the route by the
same error as the car. Their distance from the car is what the LiDAR measured, and that is
what is used here.

A vehicle track (car, truck, motorcycle) queues the car when, along the route (stations on
the pass of the route nearest the car's, `world.hdmap.RoadMap.local_coordinates`), its rear
(centre less half its length) is ahead of the car's front bumper by less than ``gap``
[m] (the ACC's 5 m bumper gap at a standstill behind a stopped car, `planner.acc_control`,
and room for a queue still closing up), its centre within half the lane's width of the lane
kept's centre line, and it is not crossing the lane (its velocity across the route below
``crossing`` [m/s]: cross traffic going by in front of a car at the line does not make a
queue of it). Standing at the line itself, the car has no vehicle in its lane that near
ahead: the junction's box beyond the line is empty, or the car waits for it to clear.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from perception.messages import ObjectClass, Track
from world.hdmap import RoadMap

VEHICLES = frozenset({ObjectClass.CAR, ObjectClass.TRUCK, ObjectClass.MOTORCYCLE})


@dataclass(frozen=True, slots=True)
class QueueParams:
    gap: float = 8.0  # [m] a vehicle's rear this near ahead of the front bumper queues the car
    crossing: float = 1.0  # [m/s] faster than this across the route, a vehicle is crossing


def queued(road: RoadMap, station: float, front: float, lane_offset: float,
           lane_width: float, tracks: Sequence[Track],
           params: QueueParams = QueueParams()) -> bool:
    """Whether a vehicle track (map frame) queues the car (module doc): the car's centre at
    `station` [m], its front bumper at `front` [m], the lane kept's centre `lane_offset` [m]
    from the reference line (left +) and `lane_width` [m] wide."""
    vehicles = [tr for tr in tracks if tr.cls in VEHICLES]
    if not vehicles:
        return False
    xy = np.array([[tr.x, tr.y] for tr in vehicles])
    s, d = road.local_coordinates(xy, station)
    heading = road.heading_at(s)
    across = np.array([-tr.vx * math.sin(h) + tr.vy * math.cos(h)
                       for tr, h in zip(vehicles, heading, strict=True)])
    rear = s - 0.5 * np.array([tr.length for tr in vehicles])
    near = (rear > front) & (rear - front < params.gap)
    in_lane = np.abs(d - lane_offset) <= 0.5 * lane_width
    return bool(np.any(near & in_lane & (np.abs(across) < params.crossing)))
