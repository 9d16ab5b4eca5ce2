"""A VLP-16-like spinning LiDAR, ray-cast against the physics world in numpy batches.

Each revolution is cast at one instant (no motion skew) from the sensor's true pose: one ray
per (channel, column), channel elevations from `LidarInfo`, columns evenly spaced over 360
deg from the sensor's forward axis, counter-clockwise, each to `max_range`. The ego's own
body is never hit (a real roof sensor's self-returns are cropped by its driver the same way).

Two ray casters give the same returns up to float32 rounding and the tessellation of
cylinders (`RayBackend`): Embree through Open3D (`world.sensors.embree_caster`, the default:
static triangles, actor boxes and the ground plane, each the nearest of three), and Bullet's
own `rayTestBatch` (`world.sensors.bullet_caster`, after culling the rays that can only meet
the ground).

Returns: range = hit fraction x max range, plus Gaussian range noise (``range_sigma``), and a
``dropout`` fraction of returns lost, both from the world's seeded generator. Points are in
the sensor frame.

In fog, rain or snow (`Lidar.extinction` alpha > 0, set from the environment:
`world.environment`) a return's received power follows the LiDAR equation for a target
filling the beam, P ~ rho exp(-2 alpha d) / d^2 (two-way extinction over the range d). Every
surface is taken as the reference reflectivity rho (the scene has no per-material
reflectivity), and the detection threshold is half the power of a return from `max_range` in
clear air (the sensor's stated range holds with a 3 dB margin), so the margin of a return
is m = 2 (max_range / d)^2 exp(-2 alpha d): detected surely where m >= 2 (every return in
clear air), lost where m < 1, and detected with probability log2(m) between (the
threshold's fluctuation: speckle, noise), drawn from the world's seeded generator. Fog's
backscatter (spurious near returns) is not modelled. Clear air draws nothing.

The body each return hit is kept beside the scan as ground truth (for perception scoring and
the recording; never given to the stack).

`Lidar` casts one `LidarInfo` in one client; `LidarSensor` is that LiDAR on the car, a
`world.sensors.sensor.Sensor` with the profile's rate and latency (`world.core.rates`).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from world.core.rates import Rate, SensorTiming
from world.ego.body import EgoTruth
from world.frames import LidarInfo, LidarScan
from world.scene.collision import CollisionShapes
from world.sensors.bullet_caster import EGO_RAY_GROUP, RAY_MASK, BulletCaster
from world.sensors.embree_caster import EmbreeCaster
from world.sensors.sensor import Reading, vehicle_pose
from world.sensors.setup import LIDAR

__all__ = ["EGO_RAY_GROUP", "RAY_MASK", "Lidar", "LidarSensor", "LidarTruth", "RayBackend",
           "beam_directions"]


class RayBackend(enum.Enum):
    """Which engine casts the rays."""

    EMBREE = "embree"  # Open3D's Embree scene + closed-form boxes and ground
    BULLET = "bullet"  # Bullet's rayTestBatch after the ground culling


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
                 actor_bodies: list[int], ground: int, static_bodies: list[int],
                 shapes: CollisionShapes, backend: RayBackend = RayBackend.EMBREE) -> None:
        """`actor_bodies`: the scenario actors' body ids, in scenario order (ground truth,
        and moving bodies); `ground`: the ground plane's body; `static_bodies`: every other
        body with collision that never moves (ego excluded); `shapes`: their collision
        shapes (the Embree caster's geometry)."""
        self.info = info
        self._actor_of = np.full(max([*actor_bodies, 0]) + 1, -1, dtype=np.int16)
        self._actor_of[actor_bodies] = np.arange(len(actor_bodies), dtype=np.int16)
        self._rng = rng
        self.extinction = 0.0  # [1/m] the air's extinction coefficient (0: clear air)
        self._dirs, self._ring, self._column = beam_directions(info)
        m = info.mount
        self._mount_xyz = np.array([m.x, m.y, m.z])
        self._mount_rot = m.rotation()
        self.backend = backend
        self.caster: EmbreeCaster | BulletCaster = (
            EmbreeCaster(client, shapes, info.max_range, actor_bodies, ground, static_bodies)
            if backend is RayBackend.EMBREE else
            BulletCaster(client, info.max_range, info.azimuth_steps, actor_bodies, ground,
                         static_bodies))

    def hide(self, bodies: frozenset[int]) -> None:
        """The actor bodies the rays pass through from now on (none: every one is met)."""
        self.caster.hide(bodies)

    @property
    def threads(self) -> int:
        """Threads the caster casts on (0: its library's choice, all cores)."""
        return self.caster.threads

    @threads.setter
    def threads(self, threads: int) -> None:
        self.caster.threads = threads

    def scan(self, t: float, vehicle_origin: NDArray[np.float64],
             vehicle_rotation: NDArray[np.float64]) -> tuple[LidarScan, LidarTruth]:
        """One revolution at time `t` for the vehicle frame's world pose (origin (3,) [m],
        rotation (3, 3) vehicle -> world)."""
        info = self.info
        rotation = vehicle_rotation @ self._mount_rot  # sensor -> world
        origin = vehicle_origin + vehicle_rotation @ self._mount_xyz
        body, fraction = self._cast(origin, self._dirs @ rotation.T,
                                    math.atan2(rotation[1, 0], rotation[0, 0]))
        keep = body >= 0
        if self.extinction > 0.0:
            keep &= self._detected(fraction * info.max_range, keep)
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

    def _detected(self, ranges: NDArray[np.float64],
                  hit: NDArray[np.bool_]) -> NDArray[np.bool_]:
        """Which rays' returns are strong enough after the air's two-way extinction (module
        doc): one draw per ray that hit something, in ray order."""
        detected = np.zeros(len(ranges), dtype=bool)
        d = np.maximum(ranges[hit], 1e-3)
        log2_margin = (1.0 + 2.0 * np.log2(self.info.max_range / d)
                       - 2.0 * self.extinction * d / math.log(2.0))
        detected[hit] = self._rng.random(len(d)) < log2_margin
        return detected

    def _cast(self, origin: NDArray[np.float64], directions: NDArray[np.float64],
              heading: float) -> tuple[NDArray[np.int32], NDArray[np.float64]]:
        """(body hit or -1, hit fraction of the max range) per ray, by the backend."""
        return self.caster.cast(origin, directions, heading)


@dataclass(frozen=True, slots=True, eq=False)
class LidarSensor:
    """A `Lidar` on the car: casts a revolution from the ego's true pose; what each return
    hit rides beside the scan as its ground truth."""

    lidar: Lidar
    timing: SensorTiming  # its entry in the rates table
    ride_height: float  # [m] the base link's origin above the vehicle frame's (the ground)
    name: str = LIDAR

    @property
    def rate(self) -> Rate:
        return self.timing.rate

    @property
    def latency(self) -> float:
        return self.timing.latency

    def capture(self, t: float, ego: EgoTruth) -> Reading:
        scan, truth = self.lidar.scan(t, *vehicle_pose(ego, self.ride_height))
        return Reading(self.name, scan, truth)
