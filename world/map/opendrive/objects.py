"""OpenDRIVE road objects (`<objects>/<object>`) as frozen dataclasses (SI units: m, rad).

An object stands at road coordinates (s, t) of its road [m], `z_offset` above the road
surface [m], turned `hdg` [rad] from the road's reference-line direction. Its size is a
box (`length` along its heading, `width` across, `height` up), a cylinder (`radius`,
`height`), an outline (corner points) or, with none of them, a point (a pole: a street
lamp). A `repeat` record lays copies (or, `distance` 0, one continuous object) along the
road from its `s` for its `length`, each attribute going linearly from its start value to
its end value.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class ObjectRepeat:
    """A `<repeat>` record: copies every `distance` [m] (0: one continuous object)."""

    s: float  # [m] where the repeat starts on the road
    length: float  # [m] along the road
    distance: float  # [m] between copies; 0: continuous
    t_start: float  # [m]
    t_end: float  # [m]
    z_offset_start: float  # [m]
    z_offset_end: float  # [m]
    height_start: float  # [m]
    height_end: float  # [m]
    width_start: float | None  # [m] None: the object's own
    width_end: float | None  # [m]
    length_start: float | None  # [m] None: the object's own
    length_end: float | None  # [m]
    radius_start: float | None  # [m] None: the object's own
    radius_end: float | None  # [m]


@dataclass(frozen=True, slots=True)
class OutlineCorner:
    """One corner of an outline: local (u, v) in the object's frame, or road (s, t)."""

    a: float  # [m] u (along the object's heading) or the road's s
    b: float  # [m] v (left of the heading) or the road's t
    z: float  # [m] of its base: above the object's origin (local) or the road (road: dz)
    height: float  # [m] up from its base


@dataclass(frozen=True, slots=True)
class Outline:
    """A polygon outline with a height at each corner (`cornerLocal` or `cornerRoad`)."""

    road_frame: bool  # True: corners are (s, t) on the road; False: (u, v) local
    corners: tuple[OutlineCorner, ...]


@dataclass(frozen=True, slots=True)
class RoadObject:
    """One `<object>` of a road (module doc)."""

    id: str
    type: str  # "pole", "tree", "barrier", "railing", "building", "streetLamp", ...
    name: str
    s: float  # [m]
    t: float  # [m] left-positive
    z_offset: float  # [m] of its base above the road surface
    hdg: float  # [rad] from the reference line's direction
    height: float  # [m] 0: flat (a road marking)
    length: float | None  # [m] along its heading (None: not given)
    width: float | None  # [m] across it
    radius: float | None  # [m] a round object's
    repeats: tuple[ObjectRepeat, ...] = ()
    outlines: tuple[Outline, ...] = ()
