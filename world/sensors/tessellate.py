"""Collision shapes (`world.scene.collision`) as triangles, for a triangle ray caster.

Boxes and triangle meshes are exact. A convex hull is triangulated from its points (Qhull,
through scipy), which gives the same solid Bullet builds from them. A cylinder becomes a
prism of `CYLINDER_SIDES` sides whose corners sit slightly outside the circle, at
``2 r / (1 + cos(pi / n))``, so that the polygon straddles the circle: the radial error is at
most ``r (1 - cos(pi / n)) / (1 + cos(pi / n))``, about ``r (pi / n)^2 / 4``, outward at the
corners and inward mid-side. Bullet's own slight rounding of a cylinder's rims (its collision
margin) is not modelled.

Everything is in the body's frame [m] (each part at its position, turned by its orientation);
triangles are (T, 3) vertex indices, counter-clockwise
seen from outside (a ray caster that ignores facing does not need it, but it keeps them
valid meshes).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from world.scene.collision import (
    IDENTITY,
    Box,
    ConvexHull,
    Cylinder,
    Part,
    Shape,
    TriangleMesh,
)
from world.scene.solids import quaternion_matrix

FloatArray = NDArray[np.float64]
IndexArray = NDArray[np.int64]
Triangles = tuple[FloatArray, IndexArray]  # vertices (V, 3) [m], triangles (T, 3)

CYLINDER_SIDES = 64  # [-] sides of a cylinder's prism

_BOX_CORNERS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
_BOX_TRIANGLES = np.array([  # corner index = 4 (x > 0) + 2 (y > 0) + (z > 0)
    [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5],  # -x, +x
    [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],  # -y, +y
    [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],  # -z, +z
])


def shape_triangles(shape: Shape) -> Triangles:
    """One shape's triangles in its own frame."""
    if isinstance(shape, Box):
        return _BOX_CORNERS * np.asarray(shape.half_extents), _BOX_TRIANGLES.copy()
    if isinstance(shape, Cylinder):
        return cylinder_triangles(shape.radius, shape.height, CYLINDER_SIDES)
    if isinstance(shape, ConvexHull):
        # imported here: scipy.spatial takes 0.65 s to import, and the sensing worker (no
        # LiDAR) and most scenes (no hulls) never need it
        from scipy.spatial import ConvexHull as Qhull

        points = np.asarray(shape.points, dtype=np.float64)
        return points, np.asarray(Qhull(points).simplices, dtype=np.int64)
    if isinstance(shape, TriangleMesh):
        return (np.asarray(shape.vertices, dtype=np.float64),
                np.asarray(shape.triangles, dtype=np.int64).reshape(-1, 3))
    raise TypeError(f"no triangles for {shape!r}")


def cylinder_triangles(radius: float, height: float, sides: int) -> Triangles:
    """A prism of `sides` sides straddling the cylinder of `radius` [m] and `height` [m]
    (along z, centred on the origin), with its two caps as fans."""
    k = np.arange(sides)
    rim = 2.0 * radius / (1.0 + math.cos(math.pi / sides))
    angle = 2.0 * math.pi * k / sides
    ring = np.column_stack([rim * np.cos(angle), rim * np.sin(angle)])
    half = 0.5 * height
    vertices = np.vstack([np.column_stack([ring, np.full(sides, -half)]),
                          np.column_stack([ring, np.full(sides, half)]),
                          [[0.0, 0.0, -half], [0.0, 0.0, half]]])
    nxt = (k + 1) % sides
    bottom, top = 2 * sides, 2 * sides + 1
    triangles = np.vstack([
        np.column_stack([k, nxt, sides + nxt]), np.column_stack([k, sides + nxt, sides + k]),
        np.column_stack([np.full(sides, bottom), nxt, k]),
        np.column_stack([np.full(sides, top), sides + k, sides + nxt]),
    ])
    return vertices, triangles


def part_triangles(part: Part) -> Triangles:
    """One part's triangles in its body's frame."""
    v, t = shape_triangles(part.shape)
    if part.orientation != IDENTITY:
        v = v @ quaternion_matrix(part.orientation).T
    return v + np.asarray(part.position), t


def body_triangles(parts: tuple[Part, ...], position: FloatArray,
                   rotation: FloatArray) -> Triangles:
    """A body's parts as one triangle set in the world frame, for the body at `position`
    (3,) [m] with `rotation` (3, 3) body -> world."""
    vertices, triangles, base = [], [], 0
    for part in parts:
        v, t = part_triangles(part)
        vertices.append(v @ rotation.T + position)
        triangles.append(t + base)
        base += len(v)
    return np.vstack(vertices), np.vstack(triangles)
