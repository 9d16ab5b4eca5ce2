"""LiDAR rays cast by Embree (Open3D's `RaycastingScene`), moving boxes and the ground in
closed form.

Three sources, the nearest return winning (ties: ground, then static, then actor):
- the flat ground z = 0 in closed form (`world.sensors.ray_culling.ground_distance`);
- every static body with collision (ego and ground excluded) as triangles
  (`world.sensors.tessellate`) in one Embree scene, built once, from the collision shapes the
  world made (`world.scene.collision.CollisionShapes`) at the bodies' poses in Bullet; each
  Embree geometry id maps back to its Bullet body id;
- the scenario actors, which are boxes, posed from Bullet at every scan, by the slab test
  (`world.sensors.box_rays`).

Precision: Embree casts in float32. The scene's vertices and the rays' origins are stored
relative to `origin`, the centre of the static scene's bounding box (rounded to 1 m), so the
coordinates stay small; a hit distance differs from Bullet's (float64) in its last float32
bits, ulp(d) ~ d x 6e-8, plus the tessellation of cylinders. Results are deterministic: the
scene is built on one thread, and each ray's result does not depend on how the rays are
split between the `threads` cast threads (0: Open3D's choice).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from world.frames import import_open3d
from world.scene.collision import Box, CollisionShapes
from world.sensors.box_rays import OrientedBox, nearest_box_hits
from world.sensors.ray_culling import ground_distance
from world.sensors.tessellate import body_triangles

HIDDEN_AT = (1.0e5, 1.0e5, -10.0)  # [m] where a hidden actor's box is cast: out of range
NO_GEOMETRY = 0xFFFFFFFF  # Open3D's INVALID_ID for a ray that met nothing


class EmbreeCaster:
    """Casts a revolution's rays against one world's static triangles, its actors' boxes
    and its ground."""

    def __init__(self, client: BulletClient, shapes: CollisionShapes, max_range: float,
                 actor_bodies: list[int], ground: int, static_bodies: list[int]) -> None:
        """Builds the static scene once; bodies as for `world.sensors.lidar.Lidar`, their
        collision shapes made through `shapes`."""
        o3d = import_open3d()
        self._c = client
        self._max_range = max_range
        self._ground = ground
        self._actors = list(actor_bodies)
        self._actor_half = [_box(shapes, b) for b in actor_bodies]
        meshes = [body_triangles(shapes.parts(b), *_pose(client, b)) for b in static_bodies]
        self.origin = _scene_origin(meshes)  # [m] world frame; the scene's coordinates
        self._scene: Any = o3d.t.geometry.RaycastingScene(nthreads=1)
        body_of = []
        for body, (vertices, triangles) in zip(static_bodies, meshes, strict=True):
            geometry = self._scene.add_triangles(
                o3d.core.Tensor((vertices - self.origin).astype(np.float32)),
                o3d.core.Tensor(triangles.astype(np.uint32)))
            body_of.append((int(geometry), body))
        self._body_of = np.full(max([g for g, _ in body_of], default=0) + 1, -1, np.int32)
        for geometry, body in body_of:
            self._body_of[geometry] = body
        self._tensor = o3d.core.Tensor
        self._rays = np.empty((0, 6), np.float32)  # origin and direction per ray: the cast's
        #   input, filled in place each scan (Open3D copies it into its tensor)
        self.threads = 0  # Embree cast threads: 0 = Open3D's choice (all cores)
        self._hidden: frozenset[int] = frozenset()  # actor bodies the rays pass through
        self._cast_static(np.array([[0, 0, 0, 1, 0, 0]], np.float32))  # commits (builds BVH)

    def cast(self, origin: NDArray[np.float64], directions: NDArray[np.float64],
             heading: float) -> tuple[NDArray[np.int32], NDArray[np.float64]]:
        """(body hit or -1, hit fraction of the max range) per unit ray (directions (N, 3)
        world frame) from `origin` (3,) [m]; `heading` is unused (the Bullet caster's
        culling needs it)."""
        max_range = self._max_range
        t_best = ground_distance(origin, directions, max_range)
        body = np.where(np.isfinite(t_best), self._ground, -1).astype(np.int32)
        if len(self._rays) != len(directions):  # allocated once per beam layout
            self._rays = np.empty((len(directions), 6), np.float32)
        rays = self._rays
        rays[:, :3] = origin - self.origin
        rays[:, 3:] = directions
        t_static, geometry = self._cast_static(rays)
        closer = (t_static < t_best) & (t_static <= max_range) & (geometry != NO_GEOMETRY)
        t_best = np.where(closer, t_static, t_best)
        body[closer] = self._body_of[geometry[closer]]
        t_actor, which = nearest_box_hits(origin, directions, max_range, self._actor_boxes())
        closer = t_actor < t_best
        t_best = np.where(closer, t_actor, t_best)
        body[closer] = np.asarray(self._actors, dtype=np.int32)[which[closer]]
        fraction = np.where(np.isfinite(t_best), t_best / max_range, 1.0)
        return body, fraction

    def _cast_static(self, rays: NDArray[np.float32]) -> tuple[NDArray[np.float64],
                                                                NDArray[np.int64]]:
        """[m] hit distances (float32 results as float64; inf: none) and geometry ids."""
        out = self._scene.cast_rays(self._tensor(rays), nthreads=self.threads)
        return (out["t_hit"].numpy().astype(np.float64),
                out["geometry_ids"].numpy().astype(np.int64))

    def hide(self, bodies: frozenset[int]) -> None:
        """The actor bodies the rays pass through (their boxes are cast far away)."""
        self._hidden = bodies

    def _actor_boxes(self) -> list[OrientedBox]:
        boxes = []
        for body, half in zip(self._actors, self._actor_half, strict=True):
            position, rotation = _pose(self._c, body)
            if body in self._hidden:
                position = np.array(HIDDEN_AT)
            boxes.append(OrientedBox(position, rotation, half))
        return boxes


def _pose(client: BulletClient, body: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A body's base position (3,) [m] and rotation (3, 3) body -> world."""
    position, quaternion = client.getBasePositionAndOrientation(body)
    rotation = np.array(client.getMatrixFromQuaternion(quaternion)).reshape(3, 3)
    return np.array(position), rotation


def _box(shapes: CollisionShapes, body: int) -> NDArray[np.float64]:
    """[m] the half extents of an actor's one box, at its body's origin."""
    parts = shapes.parts(body)
    if len(parts) != 1 or not isinstance(parts[0].shape, Box) or any(parts[0].position):
        raise ValueError(f"actor body {body} is not one centred box: {parts}")
    return np.array(parts[0].shape.half_extents)


def _scene_origin(meshes: list[tuple[NDArray[np.float64], Any]]) -> NDArray[np.float64]:
    """[m] the centre of the meshes' bounding box, rounded to whole metres (0: none)."""
    if not meshes:
        return np.zeros(3)
    points = np.vstack([v for v, _ in meshes])
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    return np.array([float(math.floor(c + 0.5)) for c in centre])
