"""Which LiDAR rays need the physics engine: the rest can only meet the flat ground.

Ray casting in Bullet costs per ray, much of it in the Python binding; but most of a
revolution sees only the ground plane (z = 0, the world's one unbounded collision shape) or
nothing: a ray whose segment, up to where it meets the ground (or its maximum range),
passes through no other body's axis-aligned bounding box cannot hit anything else. Its
result is exact in closed form: the ground at ``t = -o_z / d_z`` along the ray when it
points down and that is within range, else no return. Only the rays that cross a box go to
`rayTestBatch`, which stays the authority on every hit that is not the flat ground.

Boxes come from Bullet (`getAABB`, collision margins included, so they are conservative):
static bodies once, moving ones (NPCs) at every scan. Each box marks the columns of the
revolution whose azimuths can reach it (its corners' azimuth span seen from the sensor, plus
a margin for the body's roll and pitch, which tilt the beams' azimuths; a sensor inside its
footprint marks them all) with its horizontal distance and its top. A ray is cast when it
reaches its column's nearest box below that column's highest top (the share of rays cast
and the time saved are in `make bench`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
Box = tuple[FloatArray, FloatArray]  # (lo (3,), hi (3,)) world-frame AABB corners [m]

AZIMUTH_MARGIN = math.radians(3.0)  # [rad] beyond a box's azimuth span (body tilt)


def ground_distance(origin: FloatArray, directions: FloatArray, max_range: float) -> FloatArray:
    """[m] distance along each unit ray (N, 3) from `origin` to the plane z = 0, or +inf when
    the ray does not point down or meets it beyond `max_range`."""
    dz = directions[:, 2]
    t = np.full(len(directions), np.inf)
    down = dz < -1e-12
    t[down] = -origin[2] / dz[down]
    t[t > max_range] = np.inf
    return t


def column_span(origin: FloatArray, box: Box, heading: float, columns: int) -> range | None:
    """The revolution columns (may run past `columns`: take them modulo) whose azimuths can
    reach `box`, for a sensor at `origin` whose column 0 points along world yaw `heading`;
    None for every column (the sensor is inside the box's footprint)."""
    lo, hi = box
    if lo[0] <= origin[0] <= hi[0] and lo[1] <= origin[1] <= hi[1]:
        return None
    angles = [math.atan2(y - origin[1], x - origin[0]) - heading
              for x in (lo[0], hi[0]) for y in (lo[1], hi[1])]
    centre = angles[0]
    rel = [math.remainder(a - centre, 2.0 * math.pi) for a in angles]
    a0 = centre + min(rel) - AZIMUTH_MARGIN
    a1 = centre + max(rel) + AZIMUTH_MARGIN
    step = 2.0 * math.pi / columns
    c0 = math.floor(a0 / step)
    return range(c0, math.ceil(a1 / step) + 1)


def column_profile(origin: FloatArray, boxes: list[Box], heading: float,
                   columns: int) -> tuple[FloatArray, FloatArray]:
    """Per column of the revolution: the least horizontal distance [m] from the sensor to a
    box its azimuth can reach (+inf: none) and the highest top [m] of those boxes."""
    near = np.full(columns, np.inf)
    top = np.full(columns, -np.inf)
    for box in boxes:
        lo, hi = box
        dx = max(lo[0] - origin[0], 0.0, origin[0] - hi[0])
        dy = max(lo[1] - origin[1], 0.0, origin[1] - hi[1])
        span = column_span(origin, box, heading, columns)
        cols = (slice(None) if span is None or len(span) >= columns
                else np.mod(np.arange(span.start, span.stop), columns))
        near[cols] = np.minimum(near[cols], math.hypot(dx, dy))
        top[cols] = np.maximum(top[cols], hi[2])
    return near, top


def rays_to_cast(origin: FloatArray, directions: FloatArray, reach: FloatArray,
                 boxes: list[Box], heading: float, columns: int) -> NDArray[np.bool_]:
    """Which rays of a (rings x columns) revolution (directions (R, C, 3) world frame, reach
    (R, C) [m]) may meet a box before their reach: those whose horizontal reach gets to the
    nearest box of their column while still below that column's highest top (a ray going
    down is below any top from there on). Conservative: a box in the column, not on the
    ray, also sends the ray to the engine, which then finds what it really hits."""
    near, top = column_profile(origin, boxes, heading, columns)
    horizontal = np.hypot(directions[..., 0], directions[..., 1])
    climb = directions[..., 2] / np.maximum(horizontal, 1e-9)  # [m/m] height per metre out
    reaches = reach * horizontal >= near
    below = (climb < 0.0) | (origin[2] + near * climb <= top)
    out: NDArray[np.bool_] = reaches & below
    return out
