"""Solid shapes as data, in a body's frame: a leaf (numpy only, no PyBullet), so that code which
only describes bodies (`world.actors.shapes`) does not load the simulator.

`world.scene.collision` turns these into Bullet shapes and re-exports them; see there for
what each shape is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
Vec3 = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]  # x, y, z, w (PyBullet's order)
IDENTITY: Quaternion = (0.0, 0.0, 0.0, 1.0)


@dataclass(frozen=True, slots=True)
class Box:
    half_extents: Vec3  # [m]


@dataclass(frozen=True, slots=True)
class Cylinder:
    radius: float  # [m]
    height: float  # [m] along the part's z, centred on its origin


@dataclass(frozen=True, slots=True, eq=False)
class ConvexHull:
    points: FloatArray  # (P, 3) [m]


@dataclass(frozen=True, slots=True, eq=False)
class TriangleMesh:
    vertices: FloatArray  # (V, 3) [m]
    triangles: NDArray[np.int32]  # (T, 3) vertex indices


Shape = Box | Cylinder | ConvexHull | TriangleMesh


@dataclass(frozen=True, slots=True)
class Part:
    """One shape of a body, at `position` [m] in the body's frame, turned by `orientation`
    (a unit quaternion x, y, z, w: the shape's frame -> the body's frame)."""

    shape: Shape
    position: Vec3 = (0.0, 0.0, 0.0)
    orientation: Quaternion = IDENTITY


def quaternion_matrix(q: Quaternion) -> FloatArray:
    """(3, 3) the rotation matrix of the unit quaternion `q` (x, y, z, w)."""
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])
