"""Lane-keeping reference paths sampled from the HD map.

Stations s [m] run along the route's reference line; points are in the map frame. The path
runs with the route (increasing station) whatever the lane's travel direction, an oncoming
lane's (index < 0, `RoadMap.lane`) too: the ego drives with the route.
"""

from __future__ import annotations

import math

import numpy as np

from planner.messages import ReferencePath
from world.hdmap import FloatArray, Lane


def path_stations(
    s: float, behind: float, ahead: float, spacing: float, length: float
) -> FloatArray:
    """Stations [m] from ``s - behind`` to ``s + ahead``, clamped to the route [0, length].

    Samples are ``spacing`` [m] apart from the start, and the (clamped) end station is the
    last sample, so the final gap may be shorter. At least two samples are returned: if the
    clamped window is shorter than ``spacing`` (the car beyond the route end), it is extended
    backwards to ``spacing``. Shape (N,), N >= 2, increasing.
    """
    if spacing <= 0.0 or behind < 0.0 or ahead < 0.0:
        raise ValueError("spacing must be > 0, behind and ahead >= 0")
    if length <= 0.0:
        raise ValueError("the route has no length")
    start = min(max(s - behind, 0.0), length)
    end = min(max(s + ahead, 0.0), length)
    if end - start < spacing:
        if end < spacing:
            start, end = 0.0, min(spacing, length)
        else:
            start = end - spacing
    n = math.floor((end - start) / spacing + 1e-9)
    stations = start + spacing * np.arange(n + 1, dtype=np.float64)
    if end - stations[-1] > 1e-9 * spacing:
        stations = np.append(stations, end)
    return stations


def lane_path(
    lane: Lane,
    s: float,
    behind: float,
    ahead: float,
    spacing: float,
    *,
    length: float,
    offset: float = 0.0,
) -> ReferencePath:
    """The centre line (r = 0) of ``lane``, or the line ``offset`` [m] left of it, from
    ``s - behind`` to ``s + ahead``.

    ``s``, ``behind``, ``ahead``, ``spacing`` [m] are stations / station distances along the
    route's reference line; on an offset lane in a curve the points are about ``spacing``
    apart (scaled by ``1 - k * offset``). ``length`` [m] is the route length
    (`RoadMap.length`): lanes end at the route end, so the window is clamped to [0, length].
    Headings [rad] and signed curvatures [1/m] come from the map, not from differencing
    (the centre line's curvature, also for an offset line).
    """
    stations = path_stations(s, behind, ahead, spacing, length)
    xy = np.asarray(lane.position(stations, np.full_like(stations, offset)), dtype=np.float64)
    heading = np.asarray(lane.heading_at(stations), dtype=np.float64)
    curvature = np.asarray(lane.curvature_at(stations), dtype=np.float64)
    return ReferencePath(xy=xy.reshape(-1, 2), heading=heading, curvature=curvature)
