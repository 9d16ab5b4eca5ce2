"""A VLP-16-like spinning LiDAR, ray-cast against the physics world in numpy batches.

Each revolution is cast at one instant (no motion skew) from the sensor's true pose: one ray
per (channel, column), channel elevations from `LidarInfo`, columns evenly spaced over 360
deg from the sensor's forward axis, counter-clockwise. Rays go to `max_range` in batches of at
most 16,383 (`rayTestBatch`'s limit; 16,384 silently drops a ray), as (N, 3) numpy arrays,
on all cores (``numThreads=0``). The ego's own body is in a collision group the rays skip
(a real roof sensor's self-returns are cropped by its driver the same way).

Returns: range = hit fraction x max range, plus Gaussian range noise (``range_sigma``), and a
``dropout`` fraction of returns lost, both from the world's seeded generator. Points are in
the sensor frame. The body each return hit is kept beside the scan as ground truth (for
perception scoring and the recording; never given to the stack).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from world.frames import LidarInfo, LidarScan

MAX_BATCH = 16_383  # rays per rayTestBatch call
EGO_RAY_GROUP = 0x40  # collision group of the ego's links; the rays' mask leaves it out
RAY_MASK = 0xFFFF & ~EGO_RAY_GROUP


@dataclass(frozen=True, slots=True, eq=False)
class LidarTruth:
    """What each return of a scan really hit (ground truth, same order as the points)."""

    actor: NDArray[np.int16]  # (N,) index of the scenario actor hit, -1 for anything else


def beam_directions(info: LidarInfo) -> tuple[NDArray[np.float64], NDArray[np.uint8],
                                              NDArray[np.uint16]]:
    """Unit ray directions (channels x columns, 3) in the sensor frame, ring-major, with
    each ray's ring and column."""
    elevation = np.asarray(info.elevations)[:, None]
    azimuth = 2.0 * np.pi * np.arange(info.azimuth_steps)[None, :] / info.azimuth_steps
    directions = np.stack(np.broadcast_arrays(np.cos(elevation) * np.cos(azimuth),
                                              np.cos(elevation) * np.sin(azimuth),
                                              np.sin(elevation)), axis=-1).reshape(-1, 3)
    ring, column = np.indices((info.channels, info.azimuth_steps))
    return directions, ring.reshape(-1).astype(np.uint8), column.reshape(-1).astype(np.uint16)


class Lidar:
    """Casts one `LidarInfo` in one client."""

    def __init__(self, client: BulletClient, info: LidarInfo, rng: np.random.Generator,
                 actor_bodies: list[int]) -> None:
        """`actor_bodies`: the scenario actors' body ids, in scenario order (ground truth)."""
        self.info = info
        self._actor_of = np.full(max([*actor_bodies, 0]) + 1, -1, dtype=np.int16)
        self._actor_of[actor_bodies] = np.arange(len(actor_bodies), dtype=np.int16)
        self._c = client
        self._rng = rng
        self._dirs, self._ring, self._column = beam_directions(info)
        m = info.mount
        self._mount_xyz = np.array([m.x, m.y, m.z])
        self._mount_rot = m.rotation()

    def scan(self, t: float, vehicle_origin: NDArray[np.float64],
             vehicle_rotation: NDArray[np.float64]) -> tuple[LidarScan, LidarTruth]:
        """One revolution at time `t` for the vehicle frame's world pose (origin (3,) [m],
        rotation (3, 3) vehicle -> world)."""
        info = self.info
        rotation = vehicle_rotation @ self._mount_rot  # sensor -> world
        origin = vehicle_origin + vehicle_rotation @ self._mount_xyz
        ends = origin + (self._dirs @ rotation.T) * info.max_range
        starts = np.broadcast_to(origin, ends.shape)
        results: list[tuple[object, ...]] = []
        for i in range(0, len(ends), MAX_BATCH):
            results += self._c.rayTestBatch(starts[i:i + MAX_BATCH], ends[i:i + MAX_BATCH],
                                            numThreads=0, collisionFilterMask=RAY_MASK)
        body = np.fromiter((r[0] for r in results), dtype=np.int32, count=len(results))
        fraction = np.fromiter((r[2] for r in results), dtype=np.float64, count=len(results))
        keep = body >= 0
        if info.dropout > 0.0:
            keep &= self._rng.random(len(body)) >= info.dropout
        ranges = fraction[keep] * info.max_range
        if info.range_sigma > 0.0:
            ranges = ranges + self._rng.normal(0.0, info.range_sigma, len(ranges))
        points = (self._dirs[keep] * ranges[:, None]).astype(np.float32)
        scan = LidarScan(t=t, info=info, points=points, ring=self._ring[keep],
                         column=self._column[keep])
        hit = body[keep]
        actor = np.full(len(hit), -1, dtype=np.int16)
        known = hit < len(self._actor_of)
        actor[known] = self._actor_of[hit[known]]
        return scan, LidarTruth(actor=actor)
