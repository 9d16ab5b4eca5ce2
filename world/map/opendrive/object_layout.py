"""An OpenDRIVE file's road objects as static solids in the map frame (`SceneryObjectSpec`).

The map frame is the file's inertial frame (the route keeps it: `OdrRoute.point`); the
ground is flat (a file with elevation is refused), so an object's base stands `zOffset`
above z = 0. Each object of each file road becomes:

- a `radius`: an upright cylinder; a `length` or `width`: a box turned `hdg` from the road's
  direction (a size of 0 or not given is `MIN_SIZE`); neither: a pole of radius
  `POLE_RADIUS` (a street lamp);
- an outline: the prism over its corners (the convex hull of the corners at their bases
  and tops; a concave outline is filled in);
- a `repeat` record with a `distance`: a copy every `distance` along the record, its
  t, zOffset, height, width, length and radius linear from the record's start values to its
  end values; with `distance` 0: one continuous object (a guard rail, a wall) of boxes
  along the road, each at most `MAX_PIECE` long and short enough to stay within `SAGITTA`
  of the curved road;
- height 0 (a road marking, a crosswalk): not built (the renderer paints no road objects).

An object's station is clamped to its road. Bounded: at most `MAX_SOLIDS` solids in a file,
counted before any is made (`OpenDriveError`).
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from world.map.opendrive.errors import OpenDriveError
from world.map.opendrive.model import OpenDrive, Road
from world.map.opendrive.objects import ObjectRepeat, Outline, RoadObject
from world.spec import SceneryObjectSpec

MAX_SOLIDS = 20_000  # solids built from one file's objects (the real files: under 2,500)
MIN_SIZE = 0.1  # [m] a box side the file gives as 0 or not at all
POLE_RADIUS = 0.1  # [m] an object with no size (a street lamp's pole)
MAX_PIECE = 50.0  # [m] the longest box of a continuous object
SAGITTA = 0.05  # [m] how far a continuous object's box chord may leave the curved road


def layout_objects(odr: OpenDrive) -> tuple[SceneryObjectSpec, ...]:
    """Every road object of `odr` as solids (module doc); `OpenDriveError` past the bound."""
    total = sum(_count(road, obj) for road in odr.roads for obj in road.objects)
    if total > MAX_SOLIDS:
        raise OpenDriveError(odr.path, f"its road objects make {total} solids, more than "
                                       f"{MAX_SOLIDS}")
    return tuple(solid for road in odr.roads for obj in road.objects
                 for solid in _solids(road, obj))


def _count(road: Road, obj: RoadObject) -> int:
    """How many solids `obj` makes (cheap: nothing is evaluated on the road)."""
    if not obj.repeats:
        return 1 if obj.height > 0.0 else 0
    return sum(_copies(r) if r.distance > 0.0 else _pieces(road, r) for r in obj.repeats)


def _copies(r: ObjectRepeat) -> int:
    return math.floor(r.length / r.distance + 1e-9) + 1


def _pieces(road: Road, r: ObjectRepeat) -> int:
    """The boxes of a continuous repeat: at most `MAX_PIECE` long, each chord within
    `SAGITTA` of the road's sharpest bend along it (sampled at each record's ends too)."""
    if r.length <= 0.0:
        return 1
    pv = road.plan_view
    starts = [g.s + f * g.length for g in pv.geometries for f in (0.0, 0.5)
              if r.s < g.s + f * g.length < r.s + r.length]
    s = np.concatenate([np.linspace(r.s, r.s + r.length, 64), starts])
    curvature = float(np.max(np.abs(pv.curvature(s))))
    step = MAX_PIECE if curvature == 0.0 else min(MAX_PIECE,
                                                   math.sqrt(8.0 * SAGITTA / curvature))
    return max(1, math.ceil(r.length / step))


def _point(road: Road, s: float, t: float) -> tuple[float, float, float]:
    """([m] x, [m] y, [rad] heading) of road coordinates (s, t), s clamped to the road."""
    s = min(max(s, road.plan_view.start), road.plan_view.end)
    x, y, h = road.plan_view.pose(np.array([s]))
    heading = float(h[0])
    return float(x[0]) - t * math.sin(heading), float(y[0]) + t * math.cos(heading), heading


def _solids(road: Road, obj: RoadObject) -> Iterator[SceneryObjectSpec]:
    if obj.repeats:
        for r in obj.repeats:
            yield from (_copy_solids(road, obj, r) if r.distance > 0.0
                        else _continuous(road, obj, r))
    elif obj.height > 0.0 and obj.outlines:
        yield from (_prism(road, obj, outline) for outline in obj.outlines)
    elif obj.height > 0.0:
        yield _solid(road, obj, obj.s, obj.t, obj.z_offset, obj.height,
                     (obj.length, obj.width, obj.radius))


def _solid(road: Road, obj: RoadObject, s: float, t: float, z: float, height: float,
           size: tuple[float | None, float | None, float | None]) -> SceneryObjectSpec:
    """One box, cylinder or pole of `obj` standing at (s, t), its base `z` up."""
    x, y, heading = _point(road, s, t)
    length, width, radius = size
    centre = (x, y, z + height / 2.0)
    if radius is not None and radius > 0.0:
        return SceneryObjectSpec(obj.type, centre, heading + obj.hdg,
                                 (radius, radius, height / 2.0), round=True)
    if not length and not width:
        return SceneryObjectSpec(obj.type, centre, heading + obj.hdg,
                                 (POLE_RADIUS, POLE_RADIUS, height / 2.0), round=True)
    half = (max(length or 0.0, MIN_SIZE) / 2.0, max(width or 0.0, MIN_SIZE) / 2.0,
            height / 2.0)
    return SceneryObjectSpec(obj.type, centre, heading + obj.hdg, half)


def _lerp(a: float, b: float, u: float) -> float:
    return a + (b - a) * u


def _lerp_size(a: float | None, b: float | None, own: float | None, u: float) -> float | None:
    """A repeated size at fraction `u`: from `a` to `b`, the object's own where not given."""
    start = own if a is None else a
    end = start if b is None else b
    return None if start is None or end is None else _lerp(start, end, u)


def _copy_solids(road: Road, obj: RoadObject, r: ObjectRepeat) -> Iterator[SceneryObjectSpec]:
    for k in range(_copies(r)):
        ds = k * r.distance
        u = ds / r.length if r.length > 0.0 else 0.0
        height = _lerp(r.height_start, r.height_end, u)
        if height <= 0.0:
            continue
        size = (_lerp_size(r.length_start, r.length_end, obj.length, u),
                _lerp_size(r.width_start, r.width_end, obj.width, u),
                _lerp_size(r.radius_start, r.radius_end, obj.radius, u))
        yield _solid(road, obj, r.s + ds, _lerp(r.t_start, r.t_end, u),
                     _lerp(r.z_offset_start, r.z_offset_end, u), height, size)


def _continuous(road: Road, obj: RoadObject, r: ObjectRepeat) -> Iterator[SceneryObjectSpec]:
    """Boxes chord by chord along a continuous repeat (module doc)."""
    n = _pieces(road, r)
    for i in range(n):
        ua, ub, um = i / n, (i + 1) / n, (i + 0.5) / n
        height = _lerp(r.height_start, r.height_end, um)
        if height <= 0.0:
            continue
        xa, ya, _ = _point(road, r.s + ua * r.length, _lerp(r.t_start, r.t_end, ua))
        xb, yb, heading = _point(road, r.s + ub * r.length, _lerp(r.t_start, r.t_end, ub))
        chord = math.hypot(xb - xa, yb - ya)
        yaw = math.atan2(yb - ya, xb - xa) if chord > 0.0 else heading
        width = _lerp_size(r.width_start, r.width_end, obj.width, um) or 0.0
        z = _lerp(r.z_offset_start, r.z_offset_end, um)
        yield SceneryObjectSpec(obj.type, ((xa + xb) / 2.0, (ya + yb) / 2.0, z + height / 2.0),
                                yaw, (max(chord, MIN_SIZE) / 2.0, max(width, MIN_SIZE) / 2.0,
                                      height / 2.0))


def _prism(road: Road, obj: RoadObject, outline: Outline) -> SceneryObjectSpec:
    """The convex prism over an outline's corners, bases and tops (module doc)."""
    x0, y0, heading = _point(road, obj.s, obj.t)
    yaw = heading + obj.hdg
    points: list[tuple[float, float, float]] = []
    for c in outline.corners:
        if outline.road_frame:
            x, y, _ = _point(road, c.a, c.b)
            base = c.z
        else:
            x = x0 + c.a * math.cos(yaw) - c.b * math.sin(yaw)
            y = y0 + c.a * math.sin(yaw) + c.b * math.cos(yaw)
            base = obj.z_offset + c.z
        points += [(x, y, base), (x, y, base + (c.height or obj.height))]
    pts = np.array(points)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    mid = (lo + hi) / 2.0
    rel = tuple((float(p[0]), float(p[1]), float(p[2])) for p in pts - mid)
    half = (float(hi[0] - lo[0]) / 2.0, float(hi[1] - lo[1]) / 2.0, float(hi[2] - lo[2]) / 2.0)
    return SceneryObjectSpec(obj.type, (float(mid[0]), float(mid[1]), float(mid[2])), 0.0,
                             half, hull=rel)
