"""Lane geometry of a road across its reference line: lane offset, widths, borders.

Offsets t [m] are lateral from the reference line, left +. The centre lane (id 0) lies at
the lane offset; left lanes 1, 2, ... stack outward to the left of it, right lanes -1, -2,
... to the right. Lane widths are evaluated with s relative to their lane section's start.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from world.map.opendrive.model import FloatArray, LaneSection, OdrLane, Poly3, Road, poly3_at

SHOULDER_TYPES = frozenset({"shoulder", "stop"})  # lane types that are a hard shoulder


def lane_section_index(road: Road, s: float) -> int:
    """The index of the lane section holding station `s` [m] (the later one at a boundary,
    the first one before the road's start)."""
    starts = [sec.s for sec in road.lane_sections]
    i = int(np.searchsorted(starts, s, side="right")) - 1
    return max(0, min(i, len(starts) - 1))


def lane_offset(road: Road, s: ArrayLike) -> FloatArray:
    """[m] the centre lane's lateral offset at stations `s` (0 where no <laneOffset>)."""
    return poly3_at(road.lane_offsets, s)


def lane_width(section: LaneSection, lane: OdrLane, s: ArrayLike) -> FloatArray:
    """[m] the width of `lane` of `section` at road stations `s` (0 for the centre lane)."""
    return poly3_at(lane.widths, np.asarray(s, dtype=float) - section.s)


def constant_width(lane: OdrLane) -> float | None:
    """[m] the lane's width where it does not change along its section (one record, b = c =
    d = 0), else None."""
    widths = {(w.a, w.b, w.c, w.d) for w in lane.widths}
    if len(widths) != 1:
        return None
    (a, b, c, d), = widths
    return a if b == 0.0 and c == 0.0 and d == 0.0 else None


def lane_borders(road: Road, s: float) -> dict[int, tuple[float, float]]:
    """For each lane id of the section at station `s`: its (inner, outer) lateral offsets
    [m]; the centre lane's are both the lane offset."""
    section = road.lane_sections[lane_section_index(road, s)]
    centre = float(lane_offset(road, s))
    borders = {0: (centre, centre)}
    for sign, side in ((1.0, section.left), (-1.0, section.right)):
        t = centre
        for lane in side:
            outer = t + sign * float(lane_width(section, lane, s))
            borders[lane.id] = (t, outer)
            t = outer
    return borders


def lane_centre_t(road: Road, lane_id: int, s: float) -> float:
    """[m] the lateral offset of the middle of lane `lane_id` at station `s`; KeyError if the
    section there has no such lane."""
    inner, outer = lane_borders(road, s)[lane_id]
    return 0.5 * (inner + outer)


def record_at(records: tuple[Poly3, ...], s: float) -> Poly3 | None:
    """The record of `records` (ascending `s`) in force at station `s` (None before the
    first, as `poly3_at`'s default 0)."""
    i = int(np.searchsorted([r.s for r in records], s, side="right")) - 1
    return records[i] if i >= 0 else None


def shifted(record: Poly3 | None, start: float, origin: float) -> FloatArray:
    """[m, 1, 1/m, 1/m^2] the record's cubic (starting at station start + record.s) as
    coefficients of x = s - origin, ascending powers (zeros for None)."""
    if record is None:
        return np.zeros(4)
    x0 = origin - (start + record.s)  # the record's ds at x = 0
    a, b, c, d = record.a, record.b, record.c, record.d
    return np.array([a + x0 * (b + x0 * (c + x0 * d)), b + x0 * (2.0 * c + 3.0 * d * x0),
                     c + 3.0 * d * x0, d])


def border_polynomials(road: Road, s: float, origin: float) -> dict[int, FloatArray]:
    """For each lane id of the section at station `s`: the lateral offset t [m] of the
    lane's outer border, with the width and lane-offset records in force at `s`, as cubic
    coefficients (4,) of x = station - `origin`, ascending powers; id 0 (the centre lane):
    the lane offset. Exact where those records hold (a piece between record starts)."""
    section = road.lane_sections[lane_section_index(road, s)]
    centre = shifted(record_at(road.lane_offsets, s), 0.0, origin)
    out = {0: centre}
    for sign, side in ((1.0, section.left), (-1.0, section.right)):
        t = centre
        for lane in side:
            t = t + sign * shifted(record_at(lane.widths, s - section.s), section.s, origin)
            out[lane.id] = t
    return out
