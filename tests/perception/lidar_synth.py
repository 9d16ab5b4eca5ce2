"""A small numpy LiDAR ray caster for perception tests (no PyBullet).

The scene, in the VEHICLE frame (x forward, y left, z up, origin on the ground below the car
centre): a ground plane ``z = tan(pitch) x + tan(roll) y + offset`` (flat ground seen from a
pitched/rolled body; ``pitch > 0`` = nose down, the ground rises ahead) and a list of
oriented boxes (yaw about z). Rays are the `LidarInfo` beams (same layout as
`world.sensors.lidar.beam_directions`), cast from the sensor mount; the nearest hit within
``max_range`` is returned, with optional Gaussian range noise and dropout from a seeded
generator. Points are in the SENSOR frame, like a real `LidarScan`.

The box intersection is the slab method, vectorised over the rays, one box at a time; a
triangle mesh (a shaped body's parts, `world.actors.shapes.mesh.part_mesh`) is cast by
Open3D's ray casting scene.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from world.actors.catalogue import CATALOGUE
from world.frames import LidarInfo, LidarScan, SensorMount, import_open3d
from world.sensors.lidar import beam_directions

FloatArray = NDArray[np.float64]

LIDAR_ELEVATIONS = tuple(math.radians(e) for e in range(-15, 16, 2))  # [rad] VLP-16-like
LIDAR_MOUNT = SensorMount(0.0, 0.0, 1.57)  # [m] roof, as in world.sensor_setup

# (length, width, height) [m] of the simulator's actors: the default car and truck of the
# vehicle catalogue (a sedan, a rigid truck), which the detector's generic priors do not equal
CAR = (CATALOGUE["sedan"].length, CATALOGUE["sedan"].width, CATALOGUE["sedan"].height)
TRUCK = (CATALOGUE["rigid_truck"].length, CATALOGUE["rigid_truck"].width,
         CATALOGUE["rigid_truck"].height)
PEDESTRIAN = (0.5, 0.6, 1.75)
OBSTACLE = (1.0, 1.0, 1.0)


def lidar_info(columns: int = 1800, range_sigma: float = 0.02, dropout: float = 0.0,
               mount: SensorMount = LIDAR_MOUNT) -> LidarInfo:
    """The VLP-16-like LiDAR of the simulator (1800 or 900 columns)."""
    return LidarInfo(elevations=LIDAR_ELEVATIONS, azimuth_steps=columns, max_range=100.0,
                     mount=mount, range_sigma=range_sigma, dropout=dropout)


@dataclass(frozen=True, slots=True)
class Box:
    """An oriented box in the vehicle frame."""

    x: float  # [m] centre
    y: float  # [m]
    z: float  # [m] centre height
    length: float  # [m] along the box's heading
    width: float  # [m]
    height: float  # [m]
    yaw: float = 0.0  # [rad] heading, counter-clockwise from the vehicle's x


def on_ground(x: float, y: float, size: tuple[float, float, float], yaw: float = 0.0) -> Box:
    """A box of ``size`` (length, width, height) [m] standing on z = 0 at (x, y) [m]."""
    length, width, height = size
    return Box(x, y, 0.5 * height, length, width, height, yaw)


@dataclass(frozen=True, slots=True)
class Ground:
    """The ground plane as seen in the vehicle frame."""

    pitch: float = 0.0  # [rad] body pitch, nose down +: the ground rises ahead
    roll: float = 0.0  # [rad] body roll: the ground rises to the left for roll > 0
    offset: float = 0.0  # [m] ground height below the vehicle origin


FLAT = Ground()  # level ground at z = 0


def ground_hits(origin: FloatArray, dirs: FloatArray, ground: Ground) -> FloatArray:
    """(rays,) ray parameter [m] of the ground hit, inf where the ray misses it."""
    a, b = math.tan(ground.pitch), math.tan(ground.roll)
    denom = dirs[:, 2] - a * dirs[:, 0] - b * dirs[:, 1]
    num = a * origin[0] + b * origin[1] + ground.offset - origin[2]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = num / denom
    return np.where(t > 0.0, t, np.inf)


def box_hits(origin: FloatArray, dirs: FloatArray, box: Box) -> FloatArray:
    """(rays,) ray parameter [m] of the entry into ``box`` (slab method), inf on a miss."""
    c, s = math.cos(box.yaw), math.sin(box.yaw)
    rot = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])  # vehicle -> box
    o = rot @ (origin - np.array([box.x, box.y, box.z]))
    d = dirs @ rot.T
    half = 0.5 * np.array([box.length, box.width, box.height])
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (-half - o) / d
        t2 = (half - o) / d
    t_near = np.nanmax(np.minimum(t1, t2), axis=1)
    t_far = np.nanmin(np.maximum(t1, t2), axis=1)
    hit = (t_near <= t_far) & (t_near > 0.0)
    return np.where(hit, t_near, np.inf)


Mesh = tuple[FloatArray, NDArray[np.int64]]  # vertices (V, 3) [m], vehicle frame; triangles


def mesh_hits(origin: FloatArray, dirs: FloatArray, meshes: Sequence[Mesh]) -> FloatArray:
    """(rays,) ray parameter [m] of the nearest hit on ``meshes``, inf on a miss."""
    if not meshes:
        return np.full(len(dirs), np.inf)
    o3d = import_open3d()
    scene = o3d.t.geometry.RaycastingScene()
    for vertices, triangles in meshes:
        scene.add_triangles(o3d.core.Tensor(vertices.astype(np.float32)),
                            o3d.core.Tensor(triangles.astype(np.uint32)))
    rays = np.column_stack([np.broadcast_to(origin, dirs.shape), dirs]).astype(np.float32)
    t_hit = scene.cast_rays(o3d.core.Tensor(rays))["t_hit"].numpy().astype(np.float64)
    out: FloatArray = np.where(np.isfinite(t_hit), t_hit, np.inf)
    return out


def cast(info: LidarInfo, boxes: Sequence[Box] = (), ground: Ground | None = FLAT,
         t: float = 0.0, seed: int | None = 0, meshes: Sequence[Mesh] = ()) -> LidarScan:
    """One scan of the scene (``meshes``: triangle meshes, vehicle frame); ``ground=None``
    for no ground; ``seed=None`` for no noise."""
    dirs_sensor, ring, column = beam_directions(info)
    mount = info.mount
    origin = np.array([mount.x, mount.y, mount.z])
    dirs = dirs_sensor @ mount.rotation().T
    rng = np.full(len(dirs), np.inf)
    if ground is not None:
        rng = np.minimum(rng, ground_hits(origin, dirs, ground))
    for box in boxes:
        rng = np.minimum(rng, box_hits(origin, dirs, box))
    rng = np.minimum(rng, mesh_hits(origin, dirs, meshes))
    keep = rng <= info.max_range
    if seed is not None:
        gen = np.random.default_rng(seed)
        if info.range_sigma > 0.0:
            rng = rng + gen.normal(0.0, info.range_sigma, len(rng))
        if info.dropout > 0.0:
            keep &= gen.random(len(rng)) >= info.dropout
    points = (dirs_sensor[keep] * rng[keep, None]).astype(np.float32)
    return LidarScan(t=t, info=info, points=points, ring=ring[keep], column=column[keep])
