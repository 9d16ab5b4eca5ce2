"""The far carriageway of an OpenDRIVE dual carriageway, as a scenery road: drawn in the
world, not on the HD map the stack reads, no traffic rules from it.

A road has a far side where its lane sections have driving lanes left of the reference line
that do not adjoin the route's (`route`: a median of non-driving lanes, border, median,
restricted, none, ..., between them). Only the first run of driving lanes left of the
reference line is the far carriageway (one per road); driving lanes beyond another median
are not drawn.

The scenery road runs along its own traffic's direction (right-hand traffic: against the
file's s). Across, from each lane section, mirrored from the route's (`route._layout`):

- lane 0 is its outermost driving lane (the one farthest left of the reference line, id 5
  on the ALKS roads), lanes 1, 2, ... towards the reference line;
- its shoulder: the lane beyond lane 0 when its type is `shoulder` or `stop`, else none;
- its paint: each lane's road mark on its outer border (`lane_paint`);
- its speed limit and zone: the route's over the same stretch of the file.

Geometry, exact as the route's offset arcs (`route._offset_segments`): each arc spline
piece of the reference line offset sideways by lane 0's constant centre offset `ref_t`
(curvature k / (1 - k t), length L (1 - k t), start point moved along the normal), then
reversed (the piece's end point its start, heading + pi, curvature negated, same length;
the pieces in reverse order).

Drawn only where that is exact: every lane from the reference line out to the far
carriageway's shoulder constant along the road (one width record, b = c = d = 0), its
driving lanes equally wide, the same in every lane section, no lane offset, and the route
itself built from offset arcs (`route`: uniform). A road whose lanes vary (the route's
fitted path), whose reference line curves tighter than the far side's outer paved edge, or
whose far lanes carry road marks not supported yet (`lane_paint`; the file is not refused
for its scenery), has no far side drawn.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from world.hdmap import LinePaint, Zone
from world.map.opendrive.arcspline import ArcPiece, piece_points
from world.map.opendrive.errors import OpenDriveError
from world.map.opendrive.lane_paint import carriageway_paint
from world.map.opendrive.lanes import SHOULDER_TYPES, constant_width
from world.map.opendrive.model import LaneSection, OdrLane, OpenDrive, Road
from world.spec import RoadSpec, SegmentSpec


@dataclass(frozen=True, slots=True)
class FarLayout:
    """A lane section's far carriageway (module doc)."""

    lane_ids: tuple[int, ...]  # OpenDRIVE ids of its lanes 0, 1, ... (outermost first)
    lane_width: float  # [m] every one of its driving lanes'
    shoulder: float  # [m] its hard shoulder's width, 0 for none
    ref_t: float  # [m] lane 0's centre offset from the reference line (left +)
    paint: LinePaint

    @property
    def outer_t(self) -> float:
        """[m] the offset of its outer paved edge (the shoulder's outer border)."""
        return self.ref_t + 0.5 * self.lane_width + self.shoulder


def far_layout(odr: OpenDrive, section: LaneSection) -> FarLayout | None:
    """The far carriageway of `section`'s left lanes (the first run of driving lanes), if
    it has one and it is constant (module doc); None else. The caller knows that those
    lanes do not adjoin the route's."""
    left = section.left
    first = next((i for i, lane in enumerate(left) if lane.type == "driving"), None)
    if first is None:
        return None
    end = first
    while end < len(left) and left[end].type == "driving":
        end += 1
    drive = left[first:end]  # nearest the reference line first
    hard = left[end] if end < len(left) and left[end].type in SHOULDER_TYPES else None
    widths = _constant_widths([*left[:end], *([hard] if hard is not None else [])])
    if widths is None or len(set(widths[first:end])) != 1:
        return None
    w = widths[first]
    ref_t = sum(widths[:first]) + (len(drive) - 0.5) * w
    shoulder = widths[end] if hard is not None else 0.0
    inside = left[first - 1] if first > 0 else section.center
    return FarLayout(tuple(lane.id for lane in reversed(drive)), w, shoulder, ref_t,
                     carriageway_paint(odr, drive, inside))


def _constant_widths(lanes: Sequence[OdrLane]) -> list[float] | None:
    """[m] each lane's constant width (`constant_width`), None if one of them varies."""
    widths = [constant_width(lane) for lane in lanes]
    return None if None in widths else [w for w in widths if w is not None]


def far_side(odr: OpenDrive, road: Road, pieces: Sequence[ArcPiece],
             limits: Sequence[tuple[float, Zone]]) -> RoadSpec | None:
    """The far carriageway of `road` as a scenery road (module doc), from the reference
    line's arc spline `pieces` (in s order) and the route's ([m/s] limit, zone) on each;
    None where the road has none or it is not drawn."""
    try:
        layouts = {far_layout(odr, section) for section in road.lane_sections}
    except OpenDriveError:  # road marks the route would refuse: scenery refuses no file
        return None
    if len(layouts) != 1:
        return None
    (far,) = layouts
    if far is None or any(not 1.0 - p.curvature * far.outer_t > 0.0 for p in pieces):
        return None
    segments = tuple(_reversed_offset(piece, far, limit, zone)
                     for piece, (limit, zone) in zip(reversed(pieces), reversed(limits),
                                                     strict=True))
    first = segments[0]
    assert first.start is not None and first.speed_limit is not None
    return RoadSpec(segments, first.speed_limit, origin=first.start)


def _reversed_offset(piece: ArcPiece, far: FarLayout, limit: float,
                     zone: Zone) -> SegmentSpec:
    """The far carriageway's segment along `piece`: the piece offset by `far.ref_t`, run
    backwards (module doc)."""
    t = far.ref_t
    scale = 1.0 - piece.curvature * t
    heading = piece.heading0
    offset = ArcPiece(0.0, piece.length * scale, piece.curvature / scale,
                      piece.x0 - t * math.sin(heading), piece.y0 + t * math.cos(heading),
                      heading)
    x, y = piece_points(offset, np.array([offset.length]))
    end_heading = heading + piece.curvature * piece.length  # the offset arc turns as much
    start = (float(x[0]), float(y[0]), math.remainder(end_heading + math.pi, math.tau))
    return SegmentSpec(length=offset.length, curvature=-offset.curvature,
                       lanes=len(far.lane_ids), oncoming_lanes=0, lane_width=far.lane_width,
                       shoulder=far.shoulder, speed_limit=limit, zone=zone, start=start,
                       paint=far.paint)
