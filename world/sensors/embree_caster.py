"""LiDAR rays cast by Embree (Open3D's `RaycastingScene`), moving boxes and the ground in
closed form.

Three sources, the nearest return winning (ties: ground, then static, then actor):
- the flat ground z = 0 in closed form (`world.sensors.ray_culling.ground_distance`);
- every static body with collision (ego and ground excluded) as triangles
  (`world.sensors.tessellate`) in one Embree scene, built once, from the collision shapes the
  world made (`world.scene.collision.CollisionShapes`) at the bodies' poses in Bullet; each
  Embree geometry id maps back to its Bullet body id;
- the scenario actors, posed from Bullet at every scan, each a piece per (body, link): the
  base (link -1, posed by `getBasePositionAndOrientation`) and each link of an articulated
  body (a walker's legs, arms and head, posed by one `getLinkStates` per body: the link
  frames Bullet's last pose left, `CollisionShapes.links` giving their parts). A piece that
  is one box centred on its frame is cast by the slab test in closed form
  (`world.sensors.box_rays`); any other (a shaped body's convex parts, a link's hull) by a
  broad phase, the slab test on the piece's bounding box (for an articulated body, first on
  the box around all its pieces: the rays that miss it skip every link), then a narrow
  phase: only the rays through that box, taken into the piece's frame, cast against the
  piece's own Embree scene of its triangles, built once in that frame (pieces of the same
  parts share one scene). A ray's distance is the same in either frame (a rotation and a
  shift), and the small coordinates of a body's own frame keep float32 precise.

Precision: Embree casts in float32. The scene's vertices and the rays' origins are stored
relative to `origin`, the centre of the static scene's bounding box (rounded to 1 m), so the
coordinates stay small; a hit distance differs from Bullet's (float64) in its last float32
bits, ulp(d) ~ d x 6e-8, plus the tessellation of cylinders. Results are deterministic: the
scene is built on one thread, and each ray's result does not depend on how the rays are
split between the `threads` cast threads (0: Open3D's choice).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from world.frames import import_open3d
from world.scene.collision import IDENTITY, Box, CollisionShapes, Part
from world.sensors.box_rays import OrientedBox, nearest_box_hits, rays_through
from world.sensors.ray_culling import ground_distance
from world.sensors.tessellate import body_triangles

NO_GEOMETRY = 0xFFFFFFFF  # Open3D's INVALID_ID for a ray that met nothing
BASE = -1  # the link index of a body's base


@dataclass(frozen=True, slots=True, eq=False)
class ActorPiece:
    """One rigid piece of an actor's body as the rays see it, in the piece's frame."""

    actor: int  # index of the actor (its body in `actor_bodies`)
    body: int  # Bullet body id
    link: int  # Bullet link index (`BASE`: the base)
    centre: NDArray[np.float64]  # (3,) [m] the centre of its bounding box
    half: NDArray[np.float64]  # (3,) [m] the bounding box's half extents
    scene: Any  # its Embree scene, None when the piece is that box itself


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
        self._pieces = _actor_pieces(o3d, shapes, actor_bodies)  # per body, base first
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
        t_actor, which = self._cast_actors(origin, directions)
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
        """The actor bodies the rays pass through (their pieces are not cast)."""
        self._hidden = bodies

    def _cast_actors(self, origin: NDArray[np.float64], directions: NDArray[np.float64]
                     ) -> tuple[NDArray[np.float64], NDArray[np.int32]]:
        """[m] per ray the nearest actor hit within range (+inf: none) and that actor's
        index (-1: none); equal distances keep the box pieces first, then the shaped
        pieces in order."""
        boxes: list[OrientedBox] = []  # the pieces that are boxes, by the slab test
        box_actor: list[int] = []
        shaped: list[list[tuple[ActorPiece, NDArray[np.float64], NDArray[np.float64]]]] = []
        for pieces in self._pieces:
            if pieces[0].body in self._hidden:
                continue
            posed = _posed(self._c, pieces)
            if pieces[0].scene is None:
                boxes.append(OrientedBox(*posed[0], pieces[0].half))
                box_actor.append(pieces[0].actor)
            else:
                shaped.append([(piece, *pose) for piece, pose in zip(pieces, posed, strict=True)])
        t_best, which = nearest_box_hits(origin, directions, self._max_range, boxes)
        which = np.where(which >= 0, np.asarray([*box_actor, -1], np.int32)[which], -1)
        for group in shaped:
            subset = None  # the rays through an articulated body's box (None: all)
            if len(group) > 1:
                subset, _ = rays_through(origin, directions, self._max_range, _around(group))
                if not len(subset):
                    continue
            rays = directions if subset is None else directions[subset]
            for piece, position, rotation in group:
                idx, t = self._cast_piece(piece, position, rotation, origin, rays)
                if subset is not None:
                    idx = subset[idx]
                closer = t < t_best[idx]
                t_best[idx[closer]] = t[closer]
                which[idx[closer]] = piece.actor
        return t_best, which.astype(np.int32)

    def _cast_piece(self, piece: ActorPiece, position: NDArray[np.float64],
                    rotation: NDArray[np.float64], origin: NDArray[np.float64],
                    directions: NDArray[np.float64]
                    ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """The rays through the piece's bounding box (indices) and where each meets the
        piece [m] (+inf: it passes), within range."""
        idx, _ = rays_through(origin, directions, self._max_range,
                              _bounds(piece, position, rotation))
        if not len(idx):
            return idx, np.zeros(0)
        rays = np.empty((len(idx), 6), np.float32)
        rays[:, :3] = (origin - position) @ rotation  # the piece's frame: R^T (o - p)
        rays[:, 3:] = directions[idx] @ rotation
        out = piece.scene.cast_rays(self._tensor(rays), nthreads=self.threads)
        t = out["t_hit"].numpy().astype(np.float64)
        return idx, np.where(t <= self._max_range, t, np.inf)


def _bounds(piece: ActorPiece, position: NDArray[np.float64],
            rotation: NDArray[np.float64]) -> OrientedBox:
    """The piece's bounding box posed in the world."""
    return OrientedBox(position + rotation @ piece.centre, rotation, piece.half)


def _around(group: list[tuple[ActorPiece, NDArray[np.float64], NDArray[np.float64]]]
            ) -> OrientedBox:
    """A world-axis box around the posed pieces' bounding boxes."""
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for piece, position, rotation in group:
        centre = position + rotation @ piece.centre
        reach = np.abs(rotation) @ piece.half
        lo, hi = np.minimum(lo, centre - reach), np.maximum(hi, centre + reach)
    return OrientedBox(0.5 * (lo + hi), np.eye(3), 0.5 * (hi - lo))


def _posed(client: BulletClient, pieces: tuple[ActorPiece, ...]
           ) -> list[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Each piece's frame in the world: position (3,) [m] and rotation (3, 3), its base's
    from the base's pose, its links' from one `getLinkStates` of the body."""
    out = [_pose(client, pieces[0].body)]
    links = [piece.link for piece in pieces[1:]]
    if links:
        for state in client.getLinkStates(pieces[0].body, links):
            rotation = np.array(client.getMatrixFromQuaternion(state[5])).reshape(3, 3)
            out.append((np.array(state[4]), rotation))
    return out


def _pose(client: BulletClient, body: int,
          link: int = BASE) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A body's base (or link's) position (3,) [m] and rotation (3, 3) its frame -> world."""
    if link == BASE:
        position, quaternion = client.getBasePositionAndOrientation(body)
    else:
        position, quaternion = client.getLinkState(body, link)[4:6]
    rotation = np.array(client.getMatrixFromQuaternion(quaternion)).reshape(3, 3)
    return np.array(position), rotation


def _actor_pieces(o3d: Any, shapes: CollisionShapes, bodies: list[int]
                  ) -> list[tuple[ActorPiece, ...]]:
    """Each actor body's pieces: its base's collision shape, then its links' in link order.
    A base that is one box centred on the body's frame stays that box; any other piece gets
    an Embree scene of its triangles in its frame, one per set of parts (pieces of the same
    parts share it)."""
    scenes: dict[tuple[object, ...], tuple[Any, NDArray[np.float64], NDArray[np.float64]]] = {}

    def piece(actor: int, body: int, link: int, parts: tuple[Part, ...]) -> ActorPiece:
        key = tuple((id(p.shape), p.position, p.orientation) for p in parts)
        if key not in scenes:
            scenes[key] = _piece_scene(o3d, parts)
        scene, centre, half = scenes[key]
        return ActorPiece(actor, body, link, centre, half, scene)

    out: list[tuple[ActorPiece, ...]] = []
    for actor, body in enumerate(bodies):
        parts, links = shapes.parts(body), shapes.links(body)
        if _centred_box(parts) and not links:
            box = parts[0].shape
            assert isinstance(box, Box)
            out.append((ActorPiece(actor, body, BASE, np.zeros(3),
                                   np.array(box.half_extents), None),))
            continue
        out.append((piece(actor, body, BASE, parts),
                    *(piece(actor, body, link, p) for link, p in enumerate(links))))
    return out


def _centred_box(parts: tuple[Part, ...]) -> bool:
    return (len(parts) == 1 and isinstance(parts[0].shape, Box) and not any(parts[0].position)
            and parts[0].orientation == IDENTITY)


def _piece_scene(o3d: Any, parts: tuple[Part, ...]
                 ) -> tuple[Any, NDArray[np.float64], NDArray[np.float64]]:
    """An Embree scene of `parts`' triangles in their frame, committed (its BVH built on one
    thread), and the centre and half extents [m] of their bounding box."""
    vertices, triangles = body_triangles(parts, np.zeros(3), np.eye(3))
    scene = o3d.t.geometry.RaycastingScene(nthreads=1)
    scene.add_triangles(o3d.core.Tensor(vertices.astype(np.float32)),
                        o3d.core.Tensor(triangles.astype(np.uint32)))
    scene.cast_rays(o3d.core.Tensor(np.array([[0, 0, 0, 1, 0, 0]], np.float32)), nthreads=1)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    return scene, 0.5 * (lo + hi), 0.5 * (hi - lo)


def _scene_origin(meshes: list[tuple[NDArray[np.float64], Any]]) -> NDArray[np.float64]:
    """[m] the centre of the meshes' bounding box, rounded to whole metres (0: none)."""
    if not meshes:
        return np.zeros(3)
    points = np.vstack([v for v, _ in meshes])
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    return np.array([float(math.floor(c + 0.5)) for c in centre])
