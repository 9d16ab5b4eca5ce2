"""Measures of a body made of convex parts: its bounding box, the share of that box it fills,
which part a ray meets first, its triangle count. For tests and for checking a new shape.

Each part is the intersection of its hull's half-spaces ``n . p + d <= 0`` (Qhull's facet
planes, outward unit normals `n`), which makes point-in-part and ray-part tests exact for the
solid the mesh bounds.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.spatial import ConvexHull as Qhull

from world.actors.shapes.mesh import part_mesh
from world.actors.shapes.parts import BodyPart, points
from world.scene.solids import FloatArray

INSIDE = 1e-9  # [m] a point this far outside every plane still counts as inside


def bounds(parts: Sequence[BodyPart]) -> tuple[FloatArray, FloatArray]:
    """[m] the lowest and highest corner (3,) of the parts' bounding box, body frame."""
    pts = np.vstack([points(p) for p in parts])
    return pts.min(axis=0), pts.max(axis=0)


def planes(part: BodyPart) -> FloatArray:
    """(F, 4) the part's facet planes: outward unit normal and offset, ``n . p + d <= 0``
    inside."""
    return np.asarray(Qhull(points(part)).equations, dtype=np.float64)


def volume(part: BodyPart) -> float:
    """[m^3] the part's volume."""
    return float(Qhull(points(part)).volume)


def inside(parts: Sequence[BodyPart], samples: FloatArray) -> FloatArray:
    """(N,) bool: which of the `samples` (N, 3) [m] lie in at least one part."""
    hit = np.zeros(len(samples), dtype=bool)
    for part in parts:
        eq = planes(part)
        hit |= np.all(samples @ eq[:, :3].T + eq[:, 3] <= INSIDE, axis=1)
    return hit


def filled_fraction(parts: Sequence[BodyPart], per_axis: int = 40) -> float:
    """[-] the share of the parts' bounding box that the parts fill (their union, overlaps
    counted once), sampled at the centres of a `per_axis`^3 grid of cells."""
    lo, hi = bounds(parts)
    axes = [lo[i] + (np.arange(per_axis) + 0.5) * (hi[i] - lo[i]) / per_axis for i in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    return float(inside(parts, grid).mean())


def ray_entry(part: BodyPart, origin: FloatArray, direction: FloatArray) -> float | None:
    """[m along `direction`, a unit vector] where the ray from `origin` enters the part;
    None if it misses it or starts inside it."""
    eq = planes(part)
    facing = eq[:, :3] @ direction
    height = eq[:, :3] @ origin + eq[:, 3]
    t = -height / np.where(facing == 0.0, np.inf, facing)
    if np.any((facing == 0.0) & (height > 0.0)):
        return None  # parallel to a face, outside it
    enter = float(np.max(t[facing < 0.0], initial=-np.inf))
    leave = float(np.min(t[facing > 0.0], initial=np.inf))
    if enter <= 0.0 or enter > leave:
        return None
    return enter


def first_hit(parts: Sequence[BodyPart], origin: Sequence[float],
              direction: Sequence[float]) -> BodyPart | None:
    """The part a ray from `origin` [m] along `direction` meets first; None if none."""
    o = np.asarray(origin, dtype=np.float64)
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    best: tuple[float, BodyPart] | None = None
    for part in parts:
        t = ray_entry(part, o, d)
        if t is not None and (best is None or t < best[0]):
            best = (t, part)
    return None if best is None else best[1]


def triangle_count(parts: Sequence[BodyPart]) -> int:
    """[-] the triangles of the parts' meshes."""
    return sum(len(part_mesh(p)[1]) for p in parts)
