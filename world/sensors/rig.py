"""The car's sensor rig in one physics client: cameras and LiDAR, fired at their rates.

`SensorRig.capture` renders / casts from the ego's TRUE pose (the sensors are on the real
body) and returns `SensorData`: the frames for the stack plus the LiDAR ground truth (what
each return hit) kept apart for scoring and the recording.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from world.core.client import Rate
from world.core.rendering import Renderer
from world.ego.body import EgoTruth
from world.frames import CameraFrame, LidarScan
from world.sensors.camera import Camera
from world.sensors.lidar import Lidar, LidarTruth
from world.sensors.setup import SensorSetup


@dataclass(frozen=True, slots=True, eq=False)
class SensorData:
    """What the sensors produced at one instant."""

    t: float  # [s] sim time of the capture
    frames: tuple[CameraFrame, ...]  # the cameras that fired
    scan: LidarScan | None  # the LiDAR revolution, if it fired
    scan_truth: LidarTruth | None  # ground truth of the scan (not for the stack)

    def frame(self, name: str) -> CameraFrame | None:
        return next((f for f in self.frames if f.info.name == name), None)


@dataclass(frozen=True, slots=True)
class Due:
    """Which sensors fire at one physics step."""

    cameras: tuple[str, ...]
    lidar: bool

    def __bool__(self) -> bool:
        return bool(self.cameras) or self.lidar


def vehicle_pose(truth: EgoTruth, ride_height: float) -> tuple[NDArray[np.float64],
                                                             NDArray[np.float64]]:
    """The vehicle frame's world pose: origin (3,) [m] on the ground below the car's centre
    (in the body's own down direction) and rotation (3, 3) vehicle -> world."""
    origin = truth.position - truth.rotation[:, 2] * ride_height
    return origin, truth.rotation


class SensorSchedule:
    """The sensors' rates as physics-step counters (each rate must divide 240 Hz)."""

    def __init__(self, setup: SensorSetup) -> None:
        self._cameras = tuple((c.name, Rate(f"camera_{c.name}", round(c.rate)))
                              for c in setup.cameras)
        self._lidar = Rate("lidar", round(setup.lidar.rate))
        rates = [r for _, r in self._cameras] + [self._lidar]
        self.every = min(r.every for r in rates)  # [steps] the fastest sensor's period
        if any(r.every % self.every for r in rates):
            raise ValueError("every sensor period must be a multiple of the fastest one")

    def due(self, step: int) -> Due:
        return Due(tuple(n for n, r in self._cameras if r.fires(step)), self._lidar.fires(step))


class SensorRig:
    """Cameras (when given a renderer) and LiDAR (when given a generator) of one
    `SensorSetup` in one client."""

    def __init__(self, client: BulletClient, setup: SensorSetup, ride_height: float, *,
                 renderer: Renderer | None, lidar_rng: np.random.Generator | None,
                 actor_bodies: list[int], ground: int, static_bodies: list[int]) -> None:
        self.setup = setup
        self.renderer = renderer
        self._ride_height = ride_height
        self._cameras = ({} if renderer is None else
                         {c.name: Camera(client, c, renderer) for c in setup.cameras})
        self._lidar = (None if lidar_rng is None else
                       Lidar(client, setup.lidar, lidar_rng, actor_bodies, ground,
                             static_bodies))

    @property
    def lidar_threads(self) -> int:
        """Threads the LiDAR's ray casting may use (0: all cores)."""
        return self._lidar.threads if self._lidar is not None else 0

    @lidar_threads.setter
    def lidar_threads(self, n: int) -> None:
        if self._lidar is not None:
            self._lidar.threads = n

    @property
    def has_cameras(self) -> bool:
        return bool(self._cameras)

    @property
    def has_lidar(self) -> bool:
        return self._lidar is not None

    def capture(self, t: float, truth: EgoTruth, cameras: Sequence[str],
                lidar: bool) -> SensorData:
        """Render `cameras` and (with `lidar`) cast a revolution, at time `t` [s]."""
        origin, rotation = vehicle_pose(truth, self._ride_height)
        frames = tuple(self._cameras[name].render(t, origin, rotation) for name in cameras)
        scan, scan_truth = None, None
        if lidar:
            if self._lidar is None:
                raise RuntimeError("this rig has no LiDAR")
            scan, scan_truth = self._lidar.scan(t, origin, rotation)
        return SensorData(t, frames, scan, scan_truth)
