"""LiDAR rays cast by Bullet (`rayTestBatch`), after the closed-form ground culling.

Rays that can only meet the flat ground are solved in closed form and only the others are
cast (`world.sensors.ray_culling`), in batches of at most 16,383 (`rayTestBatch`'s limit;
16,384 silently drops a ray), as (N, 3) numpy arrays, on `threads` threads (0: Bullet's
choice, all cores). The ego's own body is in a collision group the rays skip. An
articulated actor (a walker) is culled by the box around its base and every link, and hidden
link by link.
"""

from __future__ import annotations

from operator import itemgetter
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from world.sensors.ray_culling import Box, ground_distance, rays_to_cast

MAX_BATCH = 16_383  # rays per rayTestBatch call
EGO_RAY_GROUP = 0x40  # collision group of the ego's links; the rays' mask leaves it out
HIDDEN_RAY_GROUP = 0x80  # collision group of an actor hidden from the LiDAR (`hide`)
RAY_MASK = 0xFFFF & ~EGO_RAY_GROUP & ~HIDDEN_RAY_GROUP
# a static body's collision filter as PyBullet makes it (Bullet's StaticFilter group, every
# group but StaticFilter in its mask): what an actor shown again gets back
STATIC_GROUP, STATIC_MASK = 0x2, -1 ^ 0x2
HIDDEN_MASK = STATIC_MASK  # a hidden actor still touches what it touched (the ego)


class BulletCaster:
    """Casts a revolution's rays in one client's collision world."""

    def __init__(self, client: BulletClient, max_range: float, columns: int,
                 actor_bodies: list[int], ground: int, static_bodies: list[int]) -> None:
        """`max_range` [m]; `columns`: the revolution's azimuth steps (the rays come
        ring-major, rings x columns); bodies as for `world.sensors.lidar.Lidar`."""
        self._c = client
        self._max_range = max_range
        self._columns = columns
        self._ground = ground
        self._actors = list(actor_bodies)
        self._links = {b: client.getNumJoints(b) for b in actor_bodies}  # [-] links per body
        self._static_boxes = [_aabb(client, b) for b in static_bodies]
        self.threads = 0  # rayTestBatch threads: 0 = Bullet's choice (all cores)
        self._hidden: frozenset[int] = frozenset()

    def hide(self, bodies: frozenset[int]) -> None:
        """The actor bodies the rays pass through: their collision group is one the rays'
        mask leaves out (contacts unchanged: their mask is kept)."""
        for body in self._hidden | bodies:
            group = HIDDEN_RAY_GROUP if body in bodies else STATIC_GROUP
            mask = HIDDEN_MASK if body in bodies else STATIC_MASK
            for link in range(-1, self._c.getNumJoints(body)):
                self._c.setCollisionFilterGroupMask(body, link, group, mask)
        self._hidden = bodies

    def cast(self, origin: NDArray[np.float64], directions: NDArray[np.float64],
             heading: float) -> tuple[NDArray[np.int32], NDArray[np.float64]]:
        """(body hit or -1, hit fraction of the max range) per unit ray (directions (N, 3)
        world frame, ring-major) from `origin` (3,) [m]; `heading` [rad]: world yaw of
        column 0."""
        max_range = self._max_range
        ground = ground_distance(origin, directions, max_range)
        reach = np.minimum(ground, max_range)
        boxes = self._static_boxes + [_aabb(self._c, b, self._links[b]) for b in self._actors
                                      if b not in self._hidden]
        shape = (len(directions) // self._columns, self._columns)
        need = rays_to_cast(origin, directions.reshape(*shape, 3), reach.reshape(shape),
                            boxes, heading, self._columns).reshape(-1)
        body = np.where(np.isfinite(ground), self._ground, -1).astype(np.int32)
        fraction = np.where(np.isfinite(ground), ground / max_range, 1.0)
        idx = np.flatnonzero(need)
        if len(idx):
            ends = origin + directions[idx] * max_range
            starts = np.broadcast_to(origin, ends.shape)
            results: list[tuple[Any, ...]] = []
            for i in range(0, len(idx), MAX_BATCH):
                results += self._c.rayTestBatch(starts[i:i + MAX_BATCH], ends[i:i + MAX_BATCH],
                                                numThreads=self.threads,
                                                collisionFilterMask=RAY_MASK)
            body[idx] = np.array(list(map(itemgetter(0), results)), dtype=np.int32)
            fraction[idx] = np.array(list(map(itemgetter(2), results)), dtype=np.float64)
        return body, fraction


def _aabb(client: BulletClient, body: int, links: int = 0) -> Box:
    """The world-axis box around a body's base and its first `links` links."""
    lo, hi = (np.array(v) for v in client.getAABB(body))
    for link in range(links):
        link_lo, link_hi = client.getAABB(body, link)
        lo, hi = np.minimum(lo, link_lo), np.maximum(hi, link_hi)
    return lo, hi
