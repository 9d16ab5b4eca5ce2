"""The route-road map kind: a `RoadSpec` (a chain of straight and arc segments with their
lane layout, limits, features and exits) laid out into the HD map (`world.hdmap.RoadMap`).

Steps: each segment becomes a reference-line piece laid from the end of the one before
(from the spec's `origin` pose), or from its own exact `start` pose where the map kind
gives one (an OpenDRIVE road's arc spline: `world.map.opendrive`), with its cross-section
(lanes, oncoming lanes, widths, shoulder, zone, the file's paint and lane profile; a zone
carries on until a segment names another); the segments are checked (`MapError`); the
speed-limit postings are the road's limit at s = 0, each segment's at its start and each
sign's at its station (of several at one station the last listed wins); each feature goes
onto the map, a traffic light as its place only: its head where the spec puts it, else on
a pole `LIGHT_AHEAD` past its stop line, `LIGHT_SIDE` right of the paved edge,
`LIGHT_HEIGHT` high, facing the route's traffic. The signal plan stays in the spec.
"""

from __future__ import annotations

import numpy as np

from world.hdmap import (
    TWO_PI,
    CrossSection,
    Feature,
    LightHead,
    Piece,
    RoadMap,
    Side,
    SpeedLimitPosting,
    SpeedLimitSign,
    TrafficLight,
    Zone,
    piece_end,
)
from world.spec import FeatureSpec, RoadSpec, TrafficLightSpec

LIGHT_AHEAD = 12.0  # [m] a road light's head stands this far past its stop line ...
LIGHT_SIDE = 1.0  # [m] ... this far right of the paved edge ...
LIGHT_HEIGHT = 3.5  # [m] ... with its housing's centre this high (a town places its own)
PROFILE_CHECKS = 33  # [-] stations where a segment's varying edges are checked against its arc


class MapError(ValueError):
    """The spec cannot be built into a map (e.g. a lane offset beyond an arc's radius)."""


def build_road_map(spec: RoadSpec) -> RoadMap:
    """The HD map of the route road `spec` (module doc); raises `MapError`."""
    if not spec.segments:
        raise MapError("road: no segments")
    pieces: list[Piece] = []
    sections: list[CrossSection] = []
    exits: list[int] = []
    s, xy, heading = 0.0, np.array(spec.origin[:2], dtype=float), float(spec.origin[2])
    zone = Zone.HIGHWAY
    for i, seg in enumerate(spec.segments):
        zone = seg.zone if seg.zone is not None else zone
        section = CrossSection(
            seg.lanes, seg.oncoming_lanes, seg.lane_width, seg.shoulder, zone, seg.paint,
            seg.profile)
        _check_segment(i, seg.length, seg.curvature, section)
        if seg.exit is not None:
            _check_exit(i, seg.exit, sections)
            exits.append(i)
        if seg.start is not None:
            xy, heading = np.array(seg.start[:2], dtype=float), float(seg.start[2])
        piece = Piece(
            s, float(seg.length), float(seg.curvature), float(xy[0]), float(xy[1]), heading
        )
        pieces.append(piece)
        sections.append(section)
        xy, heading = piece_end(piece)
        s += float(seg.length)
    postings = _speed_limit_postings(spec, [p.s0 for p in pieces])
    bare = RoadMap(tuple(pieces), tuple(sections), (), postings, tuple(exits), spec.junctions)
    features = tuple(_map_feature(bare, f) for f in sorted(spec.features, key=lambda f: f.s))
    return RoadMap(tuple(pieces), tuple(sections), features, postings, tuple(exits),
                   spec.junctions)


def light_head(road: RoadMap, light: TrafficLightSpec) -> LightHead:
    """Where `light`'s head stands on `road`: its own `head` (a town places them on the far
    corner of the junction), else on a pole past the stop line (module doc)."""
    if light.head is not None:
        return light.head
    s = light.s + LIGHT_AHEAD
    right, _ = road.paved_edges(s)
    x, y, heading = road.line.pose_one(s, float(right) - LIGHT_SIDE)
    return LightHead(x, y, LIGHT_HEIGHT, heading + np.pi)


def _map_feature(road: RoadMap, feature: FeatureSpec) -> Feature:
    """The map's view of a spec feature: a traffic light without its signal plan."""
    if isinstance(feature, TrafficLightSpec):
        return TrafficLight(feature.s, light_head(road, feature))
    return feature


def _check_exit(i: int, side: Side, before: list[CrossSection]) -> None:
    """Raise MapError unless segment i can leave the road before it by an exit."""
    if i == 0:
        raise MapError("road.segments.0.exit: the first segment has no road to leave")
    if side is not Side.RIGHT:
        raise MapError(f"road.segments.{i}.exit: only exits on the right are simulated")


def _check_segment(i: int, length: float, curvature: float, c: CrossSection) -> None:
    """Raise MapError if the segment is empty, its arc turns more than a full circle, or
    the arc is tighter than the road's inner half (the inner paved edge would cross the
    arc's centre; a lane profile's edges checked at `PROFILE_CHECKS` stations)."""
    if not length > 0.0:
        raise MapError(f"road.segments[{i}]: length {length} m must be > 0")
    if curvature == 0.0:
        return
    if abs(curvature) * length > TWO_PI + 1e-9:
        raise MapError(
            f"road.segments[{i}]: an arc may turn at most 360 degrees (it would lie on itself)"
        )
    radius = 1.0 / abs(curvature)
    edges = (c.profile.at(np.linspace(0.0, length, PROFILE_CHECKS))[:, [0, -1]]
             if c.profile is not None else np.array([[c.right_edge, c.left_edge]]))
    inner = float(edges[:, 1].max()) if curvature > 0.0 else float(-edges[:, 0].min())
    if not radius > inner:
        side = "left" if curvature > 0.0 else "right"
        raise MapError(
            f"road.segments[{i}]: arc radius {radius:g} m is not larger than the road's "
            f"{side} (inner) edge offset {inner:g} m"
        )


def _speed_limit_postings(
    spec: RoadSpec, segment_starts: list[float]
) -> tuple[SpeedLimitPosting, ...]:
    """Postings sorted by station: the road's limit at 0, each segment's at its start,
    each speed-limit sign. Of several postings at one station the last listed wins."""
    postings = [SpeedLimitPosting(0.0, spec.speed_limit)]
    postings += [
        SpeedLimitPosting(s0, seg.speed_limit)
        for s0, seg in zip(segment_starts, spec.segments, strict=True)
        if seg.speed_limit is not None
    ]
    postings += [
        SpeedLimitPosting(f.s, f.limit) for f in spec.features if isinstance(f, SpeedLimitSign)
    ]
    by_station = {p.s: p for p in sorted(postings, key=lambda p: p.s)}  # later ones win
    return tuple(by_station.values())
