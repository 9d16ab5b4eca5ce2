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

Each part sits at its `position` [m], turned by its `orientation` (quaternion x, y, z, w). A
compound (several parts) takes boxes, cylinders and convex hulls; `createCollisionShapeArray`
has no vertex list per child, so each hull goes through a Wavefront OBJ file of its points
and triangles (written to a temporary folder, read by Bullet at once, then deleted). Bullet
reads the file's coordinates as float32 and builds the hull of those points.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import pybullet
from pybullet_utils.bullet_client import BulletClient

from world.scene.solids import (
    IDENTITY,
    Box,
    ConvexHull,
    Cylinder,
    FloatArray,
    Part,
    Quaternion,
    Shape,
    TriangleMesh,
    Vec3,
)

__all__ = ["IDENTITY", "Box", "CollisionShapes", "ConvexHull", "Cylinder", "FloatArray", "Part",
           "Quaternion", "Shape", "TriangleMesh", "Vec3"]


class CollisionShapes:
    """The collision shapes one client was given through it, by shape id and by body."""

    def __init__(self) -> None:
        self._by_shape: dict[int, tuple[Part, ...]] = {}
        self._by_body: dict[int, tuple[Part, ...]] = {}
        self._links: dict[int, tuple[tuple[Part, ...], ...]] = {}

    def create(self, client: BulletClient, *parts: Part) -> int:
        """A Bullet collision shape made of `parts`; its id."""
        if len(parts) == 1:
            shape = int(_create_one(client, parts[0]))
        else:
            shape = int(_create_array(client, parts))
        if shape < 0:
            raise ValueError(f"Bullet refused the collision shape {parts}")
        self._by_shape[shape] = parts
        return shape

    def placed(self, body: int, shape: int) -> int:
        """Note that `body` carries `shape` (made by `create`); returns `body`."""
        self._by_body[body] = self._by_shape[shape]
        return body

    def parts(self, body: int) -> tuple[Part, ...]:
        """The parts of `body`'s collision shape (KeyError: not made through this book)."""
        return self._by_body[body]

    def placed_links(self, body: int, shapes: tuple[int, ...]) -> int:
        """Note that link `i` of the articulated `body` carries `shapes[i]` (each made by
        `create`); returns `body`."""
        self._links[body] = tuple(self._by_shape[shape] for shape in shapes)
        return body

    def links(self, body: int) -> tuple[tuple[Part, ...], ...]:
        """The parts of each link's collision shape of `body`, by link index, each in its
        link's frame (empty: a body without links)."""
        return self._links.get(body, ())


def _create_one(client: BulletClient, part: Part) -> int:
    s = part.shape
    frame: dict[str, list[float]] = {}
    if part.position != (0.0, 0.0, 0.0):
        frame["collisionFramePosition"] = list(part.position)
    if part.orientation != IDENTITY:
        frame["collisionFrameOrientation"] = list(part.orientation)
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
    """A compound of boxes, cylinders and convex hulls (`createCollisionShapeArray`)."""
    kinds, halves, radii, lengths, files = [], [], [], [], []
    with tempfile.TemporaryDirectory(prefix="avsim-hulls-") as folder:
        for i, part in enumerate(parts):
            s = part.shape
            halves.append(list(s.half_extents) if isinstance(s, Box) else [0.0, 0.0, 0.0])
            radii.append(s.radius if isinstance(s, Cylinder) else 0.0)
            lengths.append(s.height if isinstance(s, Cylinder) else 0.0)
            files.append("")
            if isinstance(s, Box):
                kinds.append(pybullet.GEOM_BOX)
            elif isinstance(s, Cylinder):
                kinds.append(pybullet.GEOM_CYLINDER)
            elif isinstance(s, ConvexHull):
                kinds.append(pybullet.GEOM_MESH)
                files[-1] = str(_write_hull(Path(folder) / f"hull{i}.obj", s))
            else:
                raise ValueError(f"a compound shape takes boxes, cylinders and convex hulls, "
                                 f"not {s}")
        return int(client.createCollisionShapeArray(
            kinds, halfExtents=halves, radii=radii, lengths=lengths, fileNames=files,
            meshScales=[[1.0, 1.0, 1.0]] * len(parts),
            collisionFramePositions=[list(p.position) for p in parts],
            collisionFrameOrientations=[list(p.orientation) for p in parts]))


def _write_hull(path: Path, hull: ConvexHull) -> Path:
    """`hull` as an OBJ file at `path` (its points and their hull's triangles: Bullet reads
    only the points faces use); returns `path`."""
    # imported here: scipy.spatial takes 0.65 s to import, and most worlds have no compound
    # with hulls
    from scipy.spatial import ConvexHull as Qhull

    points = hull.points.tolist()
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in points]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in Qhull(hull.points).simplices.tolist()]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path
