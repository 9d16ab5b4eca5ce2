"""Distances between entities for the storyboard's conditions (pure numpy).

Along the route: a station difference (longitudinal) or an offset difference (lateral);
freespace subtracts the two boxes' half extents (half length along the route, half width
across it; a box's extent is taken along its own axes, not projected for its yaw to the
route), clipped at 0. Cartesian: between the reference points, or (freespace) between the
two boxes' rectangles in the map frame: 0 when they overlap (separating axes), else the
smallest distance of a corner of one to an edge of the other. Two boxes meet (a collision)
when they overlap or touch.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from avsim.run.storyboard.snapshot import EntityState
from world.map.rectangles import Corners, overlap, rectangle


def centre_station(e: EntityState) -> float:
    """[m] the route station of the box's centre."""
    return e.s + e.centre_ahead * math.cos(e.heading - e.route_heading)


def centre_offset(e: EntityState) -> float:
    """[m] the route offset of the box's centre (left +)."""
    return e.offset + e.centre_ahead * math.sin(e.heading - e.route_heading)


def longitudinal(a: EntityState, b: EntityState, freespace: bool) -> float:
    """[m] signed, + when `b` is ahead of `a` along the route; freespace: the gap between
    the boxes (0 when they overlap lengthwise), with the sign of the centres' order."""
    if not freespace:
        return b.s - a.s
    d = centre_station(b) - centre_station(a)
    gap = max(abs(d) - (a.length + b.length) / 2.0, 0.0)
    return math.copysign(gap, d)


def lateral(a: EntityState, b: EntityState, freespace: bool) -> float:
    """[m] signed, + when `b` is left of `a`; freespace: the gap across the route."""
    if not freespace:
        return b.offset - a.offset
    d = centre_offset(b) - centre_offset(a)
    gap = max(abs(d) - (a.width + b.width) / 2.0, 0.0)
    return math.copysign(gap, d)


def corners(e: EntityState) -> Corners:
    """The box's four corners in the map frame."""
    c, s = math.cos(e.heading), math.sin(e.heading)
    cx, cy = e.x + e.centre_ahead * c, e.y + e.centre_ahead * s
    return rectangle(cx, cy, e.heading, e.length, e.width)


def boxes_meet(a: EntityState, b: EntityState) -> bool:
    """Whether the two boxes overlap or touch in the map's plane (separating axes)."""
    return overlap(corners(a), corners(b), touching=True)


def _point_segment(p: NDArray[np.float64], q0: NDArray[np.float64],
                   q1: NDArray[np.float64]) -> float:
    d = q1 - q0
    n = float(d @ d)
    k = 0.0 if n == 0.0 else min(max(float((p - q0) @ d) / n, 0.0), 1.0)
    return float(np.hypot(*(p - (q0 + k * d))))


def _one_way(a: Corners, b: Corners) -> float:
    return min(_point_segment(p, b[k], b[(k + 1) % 4]) for p in a for k in range(4))


def rectangle_distance(a: Corners, b: Corners) -> float:
    """[m] the distance between two rectangles (0 when they overlap or touch)."""
    if overlap(a, b, touching=True):
        return 0.0
    return min(_one_way(a, b), _one_way(b, a))


def cartesian(a: EntityState, b: EntityState, freespace: bool) -> float:
    """[m] Euclidean: between reference points, or freespace between the boxes."""
    if freespace:
        return rectangle_distance(corners(a), corners(b))
    return math.hypot(b.x - a.x, b.y - a.y)
