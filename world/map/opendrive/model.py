"""The parsed OpenDRIVE file as frozen dataclasses (SI units: m, rad, m/s).

Stations `s` are along a road's reference line from its start [m]; the lateral offset `t` is
left-positive [m]. A record's `s` is where it starts; it holds until the next record's `s`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:
    from world.map.opendrive.geometry import PlanView
    from world.map.opendrive.objects import RoadObject
    from world.map.opendrive.signals import RoadSignal

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class Poly3:
    """a + b ds + c ds^2 + d ds^3 with ds = station - s (a width, a lane offset)."""

    s: float  # [m] start (for a lane width: sOffset, relative to its lane section's start)
    a: float  # [m]
    b: float  # [1]
    c: float  # [1/m]
    d: float  # [1/m^2]

    def value(self, ds: ArrayLike) -> FloatArray:
        """The polynomial at `ds` [m] past `s` (vectorised)."""
        u = np.asarray(ds, dtype=float)
        return np.asarray(self.a + u * (self.b + u * (self.c + u * self.d)), dtype=float)


def poly3_at(records: tuple[Poly3, ...], s: ArrayLike, default: float = 0.0) -> FloatArray:
    """The piecewise polynomial `records` (ascending `s`) at stations `s` [m]: each station
    uses the last record starting at or before it; `default` before the first (or none)."""
    st = np.asarray(s, dtype=float)
    out = np.full(st.shape, default, dtype=float)
    if not records:
        return out
    starts = np.array([r.s for r in records])
    idx = np.searchsorted(starts, st, side="right") - 1
    for i, rec in enumerate(records):
        m = idx == i
        if np.any(m):
            out[m] = rec.value(st[m] - rec.s)
    return out


@dataclass(frozen=True, slots=True)
class RoadMark:
    """A lane's outer-border marking from `s_offset` on."""

    s_offset: float  # [m] relative to the lane section's start
    type: str  # "solid", "broken", "solid solid", "none", "botts dots", ...
    color: str  # "standard", "white", "yellow", ...
    width: float  # [m] (0.12 if the file gives none)
    weight: str  # "standard" or "bold"
    lane_change: str  # "both", "increase", "decrease", "none"


@dataclass(frozen=True, slots=True)
class OdrLane:
    """One lane of a lane section (id 0: the centre lane, no width)."""

    id: int  # [1] + left of the reference line, - right, 0 centre
    type: str  # "driving", "border", "stop", "shoulder", "sidewalk", ...
    level: bool  # keep it level (no superelevation)
    widths: tuple[Poly3, ...]  # [m] s = sOffset relative to the lane section's start
    road_marks: tuple[RoadMark, ...]
    speed: float | None  # [m/s] the lane's <speed max>, None if none or "no limit"
    predecessors: tuple[int, ...] = ()  # [1] <link><predecessor id>: the lanes it continues
    #   in the section (or road) before, in the order given; () if the file names none
    successors: tuple[int, ...] = ()  # [1] <link><successor id>: the lanes after it


@dataclass(frozen=True, slots=True)
class LaneSection:
    """The lanes from station `s` until the next section."""

    s: float  # [m]
    left: tuple[OdrLane, ...]  # ids 1, 2, ... from the centre outward
    center: OdrLane  # id 0
    right: tuple[OdrLane, ...]  # ids -1, -2, ... from the centre outward

    def lane(self, lane_id: int) -> OdrLane:
        """The lane `lane_id`; KeyError if the section has none such."""
        if lane_id == 0:
            return self.center
        side = self.left if lane_id > 0 else self.right
        if abs(lane_id) > len(side):
            raise KeyError(lane_id)
        return side[abs(lane_id) - 1]


@dataclass(frozen=True, slots=True)
class Link:
    """A road's predecessor or successor."""

    element_type: str  # "road" or "junction"
    element_id: str
    contact_point: str | None  # "start", "end" or None


@dataclass(frozen=True, slots=True)
class SpeedRecord:
    """The road type's speed limit from `s` on."""

    s: float  # [m]
    max_speed: float | None  # [m/s] None: "no limit", "undefined" or not given
    road_type: str  # "motorway", "rural", "town", ...


@dataclass(frozen=True, slots=True)
class Line:
    """A straight reference line."""


@dataclass(frozen=True, slots=True)
class Arc:
    """A constant-curvature reference line."""

    curvature: float  # [1/m] + turns left


@dataclass(frozen=True, slots=True)
class Spiral:
    """A clothoid: curvature linear in the station from `curv_start` to `curv_end`."""

    curv_start: float  # [1/m]
    curv_end: float  # [1/m]


@dataclass(frozen=True, slots=True)
class Poly3Shape:
    """v = a + b u + c u^2 + d u^3 in the record's local frame (u along `hdg`)."""

    a: float  # [m]
    b: float  # [1]
    c: float  # [1/m]
    d: float  # [1/m^2]


@dataclass(frozen=True, slots=True)
class ParamPoly3:
    """u(p), v(p) cubics in the record's local frame; p in [0, 1] ("normalized") or
    [0, length] ("arcLength")."""

    au: float  # [m]
    bu: float  # [m] per unit p
    cu: float
    du: float
    av: float  # [m]
    bv: float
    cv: float
    dv: float
    p_range: Literal["arcLength", "normalized"]


Shape = Line | Arc | Spiral | Poly3Shape | ParamPoly3


@dataclass(frozen=True, slots=True)
class Geometry:
    """One planView record: the reference line from station `s` for `length`."""

    s: float  # [m]
    x: float  # [m] start position
    y: float  # [m]
    hdg: float  # [rad] start heading (counter-clockwise from +x)
    length: float  # [m]
    shape: Shape


@dataclass(frozen=True, slots=True)
class Road:
    """One <road>."""

    id: str
    name: str
    length: float  # [m]
    junction: str  # "-1" outside junctions
    rule: Literal["RHT", "LHT"]  # right- or left-hand traffic
    predecessor: Link | None
    successor: Link | None
    plan_view: PlanView
    lane_offsets: tuple[Poly3, ...]  # [m] of the centre lane from the reference line
    lane_sections: tuple[LaneSection, ...]  # ascending s, the first at 0
    speeds: tuple[SpeedRecord, ...]  # ascending s
    objects: tuple[RoadObject, ...] = ()  # its <objects> (s on this road; none on a merged
    #   road: `chain` keeps them on the file's roads)
    signals: tuple[RoadSignal, ...] = ()  # its <signals> (s on this road; none on a merged
    #   road, as objects)


@dataclass(frozen=True, slots=True)
class OpenDrive:
    """A whole .xodr file."""

    path: Path
    rev_major: int  # [1] 1
    rev_minor: int  # [1] 4..8
    name: str
    roads: tuple[Road, ...]

    def road(self, road_id: str) -> Road:
        """The road `road_id`; KeyError if none."""
        for r in self.roads:
            if r.id == road_id:
                return r
        raise KeyError(road_id)
