"""A part as a closed triangle mesh in the body frame: the surface of its convex solid.

Boxes give 12 triangles, cylinders a prism of `CYLINDER_SIDES` sides with fan caps, hulls
Qhull's triangulated facets (through scipy). Every triangle is counter-clockwise seen from
outside (its normal points out of the solid), unused points are dropped, and the order is
canonical (vertices in their input order, each triangle starting at its lowest index,
triangles sorted) so that the same part always writes the same file.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull as Qhull

from world.actors.shapes.parts import CYLINDER_SIDES, BodyPart, points
from world.scene.solids import Box, Cylinder, FloatArray

IndexArray = NDArray[np.int64]
Mesh = tuple[FloatArray, IndexArray]  # vertices (V, 3) [m], triangles (T, 3) indices

_BOX_TRIANGLES = np.array([  # corner index = 4 (x > 0) + 2 (y > 0) + (z > 0)
    [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5],  # -x, +x
    [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],  # -y, +y
    [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],  # -z, +z
], dtype=np.int64)


def _prism_triangles(sides: int) -> IndexArray:
    """A prism's triangles: rim 0 (indices 0..n-1, at -h/2) and rim 1 (n..2n-1, at +h/2),
    corners counter-clockwise about +z; caps as fans from each rim's first corner."""
    k = np.arange(sides)
    nxt = (k + 1) % sides
    fan = np.arange(1, sides - 1)
    return np.vstack([
        np.column_stack([k, nxt, sides + nxt]), np.column_stack([k, sides + nxt, sides + k]),
        np.column_stack([np.zeros(sides - 2, np.int64), fan + 1, fan]),
        np.column_stack([np.full(sides - 2, sides), sides + fan, sides + fan + 1]),
    ]).astype(np.int64)


def _hull_triangles(pts: FloatArray) -> IndexArray:
    """Qhull's triangles of `pts`, each turned to face away from the hull's centre."""
    qhull = Qhull(pts)
    tri = np.asarray(qhull.simplices, dtype=np.int64).copy()
    centre = pts[qhull.vertices].mean(axis=0)
    a, b, c = pts[tri[:, 0]], pts[tri[:, 1]], pts[tri[:, 2]]
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a - centre) < 0.0
    tri[inward] = tri[inward][:, [0, 2, 1]]
    return tri


def canonical(vertices: FloatArray, triangles: IndexArray) -> Mesh:
    """The mesh with unused vertices dropped (the rest kept in order), each triangle
    rotated to start at its lowest index (its winding kept) and the triangles sorted."""
    used = np.unique(triangles)
    renumber = np.full(len(vertices), -1, dtype=np.int64)
    renumber[used] = np.arange(len(used))
    tri = renumber[triangles]
    first = np.argmin(tri, axis=1)
    rows = np.arange(len(tri))[:, None]
    tri = tri[rows, (first[:, None] + np.arange(3)) % 3]
    tri = tri[np.lexsort((tri[:, 2], tri[:, 1], tri[:, 0]))]
    return vertices[used], tri


def part_mesh(part: BodyPart) -> Mesh:
    """The part's closed surface in the body frame."""
    pts = points(part)
    if isinstance(part.solid, Box):
        return canonical(pts, _BOX_TRIANGLES)
    if isinstance(part.solid, Cylinder):
        return canonical(pts, _prism_triangles(CYLINDER_SIDES))
    return canonical(pts, _hull_triangles(pts))
