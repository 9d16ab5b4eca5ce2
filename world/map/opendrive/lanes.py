"""Lane geometry of a road across its reference line: lane offset, widths, borders.

Offsets t [m] are lateral from the reference line, left +. The centre lane (id 0) lies at
the lane offset; left lanes 1, 2, ... stack outward to the left of it, right lanes -1, -2,
... to the right. Lane widths are evaluated with s relative to their lane section's start.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from world.map.opendrive.model import FloatArray, LaneSection, OdrLane, Road, poly3_at


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
