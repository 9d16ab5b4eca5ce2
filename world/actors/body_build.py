"""An actor's body in Bullet: its shape's convex parts, or its box.

A shaped body (`world.actors.shapes.actors`) is one kinematic (static, mass 0) body whose
collision shape is the compound of its shape's parts (boxes, rotated cylinders, convex hulls:
`world.scene.collision`) and whose visual is its parts coloured by material: one mesh per
material (an OBJ file, the only meshes every renderer draws), paint in the actor kind's
colour. An actor without a shape is one box, collision and visual. A walking pedestrian is
an articulated walker (`world.actors.walker_body`), its origin at the hips (posed by
`pose_walker`, not at its box's centre).

Frame: every body's origin is the centre of its actor's box (the pose the rest of the world
gives and reads), so a shape, whose origin is on the ground (`world.actors.shapes`), is
lowered by half the box's height. Actors of the same shape and box height share one
collision shape and one visual.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pybullet
from pybullet_utils.bullet_client import BulletClient

from world.actors.shapes.body import Body
from world.actors.shapes.materials import MATERIALS
from world.actors.shapes.mesh import part_mesh
from world.actors.shapes.parts import BodyPart
from world.actors.shapes.walker import WalkerModel
from world.actors.walker_body import build_walker
from world.scene.collision import Box, CollisionShapes, Part
from world.scene.traffic_light import write_obj

Rgba = tuple[float, float, float, float]
BELOW = (0.0, 0.0, -10.0)  # [m] where a body is made, below the ground until placed
PAINT = "paint"  # the material painted in the actor kind's colour


class BodyBuilder:
    """Makes actors' bodies in one client, keeping their collision shapes in `shapes`."""

    def __init__(self, client: BulletClient, shapes: CollisionShapes) -> None:
        self._c = client
        self._shapes = shapes
        self._made: dict[tuple[str, float, Rgba], tuple[int, int]] = {}
        self._folder: tempfile.TemporaryDirectory[str] | None = None  # the visuals' files

    def box(self, half: tuple[float, float, float], rgba: Rgba) -> int:
        """A box body of half extents `half` [m] in colour `rgba`."""
        shape = self._shapes.create(self._c, Part(Box(half)))
        visual = self._c.createVisualShape(pybullet.GEOM_BOX, halfExtents=list(half),
                                           rgbaColor=list(rgba))
        return self._body(shape, visual)

    def shaped(self, body: Body, box_height: float, paint: Rgba) -> int:
        """A body of `body`'s shape whose origin is the centre of a box `box_height` [m]
        high standing on the ground; its paint in colour `paint`."""
        key = (body.name, box_height, paint)
        if key not in self._made:
            drop = -0.5 * box_height
            parts = tuple(_collision_part(p, drop) for p in body.parts)
            self._made[key] = (self._shapes.create(self._c, *parts),
                               self._visual(body, drop, paint))
        return self._body(*self._made[key])

    def walker(self, model: WalkerModel) -> int:
        """An articulated walker of `model`, asleep, below the ground until posed."""
        body = build_walker(self._c, model, self._files(), shapes=self._shapes)
        self._c.resetBasePositionAndOrientation(body, list(BELOW), [0.0, 0.0, 0.0, 1.0])
        return body

    def _files(self) -> Path:
        """The folder of the visuals' mesh files (kept while the builder lives)."""
        if self._folder is None:
            self._folder = tempfile.TemporaryDirectory(prefix="avsim-bodies-")
        return Path(self._folder.name)

    def _body(self, shape: int, visual: int) -> int:
        return self._shapes.placed(int(self._c.createMultiBody(
            0.0, shape, visual, list(BELOW), useMaximalCoordinates=True)), shape)

    def _visual(self, body: Body, drop: float, paint: Rgba) -> int:
        """One mesh per material of `body`, lowered by -`drop` [m]."""
        folder = self._files()
        files, colours = [], []
        for name, m in MATERIALS.items():
            meshes = [part_mesh(p) for p in body.parts if p.material == name]
            if not meshes:
                continue
            vertices = np.vstack([v for v, _ in meshes]) + np.array([0.0, 0.0, drop])
            starts = np.cumsum([0] + [len(v) for v, _ in meshes[:-1]])
            faces = np.vstack([f + s for (_, f), s in zip(meshes, starts, strict=True)])
            path = folder / f"{body.name}_{len(self._made)}_{name}.obj"
            write_obj(path, vertices, faces)
            files.append(str(path))
            colours.append(list(paint) if name == PAINT else [*m.rgb, 1.0])
        n = len(files)
        return int(self._c.createVisualShapeArray(
            [pybullet.GEOM_MESH] * n, fileNames=files, meshScales=[[1.0, 1.0, 1.0]] * n,
            rgbaColors=colours))


def _collision_part(part: BodyPart, drop: float) -> Part:
    """`part` as a collision part, lowered by -`drop` [m]."""
    x, y, z = part.position
    return Part(part.solid, (x, y, z + drop), part.orientation)
