"""Road specs and maps for tests: segments by length and radius, arcs by radius and angle."""

from __future__ import annotations

import math

import numpy as np

from world.hdmap import Lane, RoadMap, Zone
from world.map.road import build_road_map
from world.spec import FeatureSpec, RoadSpec, SegmentSpec

W = 3.5  # [m] lane width used throughout
SHOULDER = 2.5  # [m]
KPH = 1.0 / 3.6  # [m/s per km/h]


def seg(
    length: float,
    radius: float = 0.0,
    *,
    lanes: int = 2,
    oncoming: int = 1,
    speed_kph: float | None = None,
    zone: Zone | None = None,
) -> SegmentSpec:
    """A segment; radius > 0 turns left, < 0 right, 0 is a straight."""
    return SegmentSpec(
        length=length,
        curvature=0.0 if radius == 0.0 else 1.0 / radius,
        lanes=lanes,
        oncoming_lanes=oncoming,
        lane_width=W,
        shoulder=SHOULDER,
        speed_limit=None if speed_kph is None else speed_kph * KPH,
        zone=zone,
    )


def arc(radius: float, angle_deg: float, *, lanes: int = 2, oncoming: int = 1) -> SegmentSpec:
    """Arc of |radius| turning by angle_deg (> 0 left)."""
    r = abs(radius)
    length = r * math.radians(abs(angle_deg))
    return seg(length, math.copysign(r, angle_deg), lanes=lanes, oncoming=oncoming)


def make_map(
    *segments: SegmentSpec, speed_kph: float = 50.0, features: tuple[FeatureSpec, ...] = ()
) -> RoadMap:
    return build_road_map(RoadSpec(tuple(segments), speed_kph * KPH, features))


def numeric_curvature(lane: Lane, s: float, h: float = 1e-3) -> float:
    """[1/m] the curvature of `lane`'s centre line at station `s` from its points: the turn
    between the chords over [s - h, s] and [s, s + h] per their mean length."""
    p = lane.position(np.array([s - h, s, s + h]), np.zeros(3))
    d1, d2 = p[1] - p[0], p[2] - p[1]
    turn = math.atan2(d1[0] * d2[1] - d1[1] * d2[0], float(np.dot(d1, d2)))
    return turn / (0.5 * (math.hypot(*d1) + math.hypot(*d2)))
