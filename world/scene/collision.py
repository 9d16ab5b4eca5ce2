"""Collision shapes as data: one description makes the Bullet shape and is kept beside it.

PyBullet does not give back the collision shapes of maximal-coordinate bodies (every static
and kinematic body here: `getCollisionShapeData` and `getMeshData` fail or return nothing for
them), yet another ray caster needs exactly that geometry. So a shape is described first,
as a tuple of `Part`s in the body's frame, and `CollisionShapes.create` turns the
description into the Bullet shape with the same calls the builders made by hand (one part:
`createCollisionShape`; several: `createCollisionShapeArray`), remembering it by shape id;
`placed` then remembers which body carries which shape.

Shapes (all in the part's frame, SI units; the data types live in the leaf `world.scene.solids`):
- `Box`: half extents along x, y, z;
- `Cylinder`: radius and full height along z, centred on the origin;
- `ConvexHull`: the convex hull of a point set (Bullet: GEOM_MESH with vertices, no indices);
- `TriangleMesh`: a static concave mesh (Bullet: GEOM_MESH with vertices and indices).
"""

from __future__ import annotations

import pybullet
from pybullet_utils.bullet_client import BulletClient

from world.scene.solids import (
    Box,
    ConvexHull,
    Cylinder,
    FloatArray,
    Part,
    Shape,
    TriangleMesh,
    Vec3,
)

__all__ = ["Box", "CollisionShapes", "ConvexHull", "Cylinder", "FloatArray", "Part", "Shape",
           "TriangleMesh", "Vec3"]


class CollisionShapes:
    """The collision shapes one client was given through it, by shape id and by body."""

    def __init__(self) -> None:
        self._by_shape: dict[int, tuple[Part, ...]] = {}
        self._by_body: dict[int, tuple[Part, ...]] = {}

    def create(self, client: BulletClient, *parts: Part) -> int:
        """A Bullet collision shape made of `parts`; its id."""
        if len(parts) == 1:
            shape = int(_create_one(client, parts[0]))
        else:
            shape = int(_create_array(client, parts))
        self._by_shape[shape] = parts
        return shape

    def placed(self, body: int, shape: int) -> int:
        """Note that `body` carries `shape` (made by `create`); returns `body`."""
        self._by_body[body] = self._by_shape[shape]
        return body

    def parts(self, body: int) -> tuple[Part, ...]:
        """The parts of `body`'s collision shape (KeyError: not made through this book)."""
        return self._by_body[body]


def _create_one(client: BulletClient, part: Part) -> int:
    s = part.shape
    frame = {} if part.position == (0.0, 0.0, 0.0) else {
        "collisionFramePosition": list(part.position)}
    if isinstance(s, Box):
        return int(client.createCollisionShape(pybullet.GEOM_BOX,
                                               halfExtents=list(s.half_extents), **frame))
    if isinstance(s, Cylinder):
        return int(client.createCollisionShape(pybullet.GEOM_CYLINDER, radius=s.radius,
                                               height=s.height, **frame))
    if isinstance(s, ConvexHull):
        return int(client.createCollisionShape(pybullet.GEOM_MESH,
                                               vertices=s.points.tolist(), **frame))
    return int(client.createCollisionShape(pybullet.GEOM_MESH, vertices=s.vertices.tolist(),
                                           indices=s.triangles.reshape(-1).tolist(), **frame))


def _create_array(client: BulletClient, parts: tuple[Part, ...]) -> int:
    """A compound of boxes and cylinders (`createCollisionShapeArray`)."""
    kinds, halves, radii, lengths = [], [], [], []
    for part in parts:
        s = part.shape
        if isinstance(s, Box):
            kinds.append(pybullet.GEOM_BOX)
            halves.append(list(s.half_extents))
            radii.append(0.0)
            lengths.append(0.0)
        elif isinstance(s, Cylinder):
            kinds.append(pybullet.GEOM_CYLINDER)
            halves.append([0.0, 0.0, 0.0])
            radii.append(s.radius)
            lengths.append(s.height)
        else:
            raise ValueError(f"a compound shape takes boxes and cylinders, not {s}")
    return int(client.createCollisionShapeArray(
        kinds, halfExtents=halves, radii=radii, lengths=lengths,
        collisionFramePositions=[list(p.position) for p in parts]))
