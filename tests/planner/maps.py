"""Maps for the planner tests: real `RoadMap`s from specs, and a straight-road test double.

The double has the `RoadMap` / `Lane` methods the planner uses, so the planner's logic is
tested even while `world.hdmap` is being reworked; the real map is used wherever it builds.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from world.hdmap import Piece, RoadMap, SpeedLimitPosting, SpeedLimitSign
from world.map.road import build_road_map
from world.spec import RoadSpec, SegmentSpec

KPH = 1.0 / 3.6  # [m/s per km/h]
LANE_WIDTH = 3.5  # [m]


def segment(length: float, radius: float | None = None, left: bool = True) -> SegmentSpec:
    """A 2 + 1 lane segment: a straight, or an arc of ``radius`` [m] turning left / right."""
    curvature = 0.0 if radius is None else (1.0 if left else -1.0) / radius
    return SegmentSpec(
        length=length,
        curvature=curvature,
        lanes=2,
        oncoming_lanes=1,
        lane_width=LANE_WIDTH,
        shoulder=2.5,
    )


def road_spec(
    segments: list[SegmentSpec], limit_kph: float, signs: tuple[tuple[float, float], ...] = ()
) -> RoadSpec:
    """``signs``: (station [m], limit [km/h]) speed-limit signs."""
    return RoadSpec(
        segments=tuple(segments),
        speed_limit=limit_kph * KPH,
        features=tuple(SpeedLimitSign(s=s, limit=v * KPH) for s, v in signs),
    )


def real_map(spec: RoadSpec) -> RoadMap:
    return build_road_map(spec)


class StraightLane:
    """Test double of `world.hdmap.Lane`: a straight lane along +x at y = offset."""

    direction = 1

    def __init__(self, index: int, offset: float) -> None:
        self.index = index
        self.offset = offset

    def offset_at(self, s: ArrayLike) -> NDArray[np.float64]:
        return np.full_like(np.asarray(s, dtype=np.float64), self.offset)

    def position(self, s: ArrayLike, r: ArrayLike) -> NDArray[np.float64]:
        s_arr, r_arr = np.broadcast_arrays(np.asarray(s, float), np.asarray(r, float))
        return np.stack([s_arr, self.offset + r_arr], axis=-1)

    def local_coordinates(
        self, xy: ArrayLike, near: float | None = None
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        pts = np.asarray(xy, dtype=np.float64)
        return pts[..., 0], pts[..., 1] - self.offset

    def heading_at(self, s: ArrayLike) -> NDArray[np.float64]:
        return np.zeros_like(np.asarray(s, dtype=np.float64))

    def curvature_at(self, s: ArrayLike) -> NDArray[np.float64]:
        return np.zeros_like(np.asarray(s, dtype=np.float64))


class StraightRoad:
    """Test double of `world.hdmap.RoadMap`: a straight two-lane road with postings."""

    def __init__(
        self, length: float, limit_kph: float, signs: tuple[tuple[float, float], ...]
    ) -> None:
        self.length = length
        self.pieces = (Piece(0.0, length, 0.0, 0.0, 0.0, 0.0),)
        postings = [(0.0, limit_kph), *sorted(signs)]
        self.speed_limits = tuple(SpeedLimitPosting(s, v * KPH) for s, v in postings)
        self.lanes = (StraightLane(0, 0.0), StraightLane(1, LANE_WIDTH))
        self.features: tuple[object, ...] = ()  # no stop lines, crossings or bumps

    def lane(self, index: int) -> StraightLane:
        return self.lanes[index]

    def speed_limit_at(self, s: ArrayLike) -> NDArray[np.float64]:
        post_s = np.array([p.s for p in self.speed_limits])
        post_v = np.array([p.limit for p in self.speed_limits])
        i = np.searchsorted(post_s, np.asarray(s, dtype=np.float64), side="right") - 1
        out: NDArray[np.float64] = post_v[np.maximum(i, 0)]
        return out


def straight_road(
    kind: str, length: float, limit_kph: float, signs: tuple[tuple[float, float], ...] = ()
) -> RoadMap:
    """A straight road, as the real map (``kind == "real"``) or the double (``"double"``)."""
    if kind == "real":
        return real_map(road_spec([segment(length)], limit_kph, signs))
    return StraightRoad(length, limit_kph, signs)  # type: ignore[return-value]
