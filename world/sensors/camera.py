"""Cameras: a pinhole `CameraInfo` rendered from the car's true pose by PyBullet.

`Camera` renders one `CameraInfo` in one client; `CameraSensor` is that camera on the car, a
`world.sensors.sensor.Sensor` with the profile's rate and latency (`world.core.rates`).

The camera's world pose is the body's pose (from the physics, pitch and roll included)
composed with the mount; the view matrix looks along the mount's x axis with its z axis up,
and the projection has the camera's vertical field of view and aspect. Lighting is Bullet's
default (no shadows: they triple TinyRenderer's cost and add nothing the lane finder needs).
Bodies the camera is told not to draw (`Camera.hidden`: a storyboard's VisibilityAction) are
moved far below the ground for the frame and put back where they were right after.
The environment in effect (`Camera.environment`, `world.environment`) is applied to each
image from its depth buffer: fog, rain, darkness and the sensor's noise
(`world.sensors.camera_weather`); clear daylight leaves the image as Bullet drew it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
import pybullet
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from world.core.quiet import quiet_c_output
from world.core.rates import Rate, SensorTiming
from world.core.rendering import Renderer
from world.ego.body import EgoTruth
from world.environment import CLEAR, SceneEnvironment
from world.frames import CameraFrame, CameraInfo
from world.sensors.camera_weather import CameraWeather, frame_key
from world.sensors.sensor import Reading, vehicle_pose

AWAY = (1.0e5, 1.0e5, -10.0)  # [m] where a body the camera does not draw is for a frame


class Camera:
    """Renders one `CameraInfo` in one client."""

    def __init__(self, client: BulletClient, info: CameraInfo, renderer: Renderer,
                 seed: tuple[int, ...] = (0,)) -> None:
        """`seed`: the entropy of its noise (the run's seed and the camera's index): each
        frame's noise is drawn from it and the frame's time."""
        self.info = info
        self.renderer = renderer
        self._c = client
        self._renderer = renderer.flag
        self._projection = client.computeProjectionMatrixFOV(
            math.degrees(info.fov_y), info.width / info.height, info.near, info.far
        )
        m = info.mount
        self._mount_xyz = np.array([m.x, m.y, m.z])  # [m] vehicle frame
        self._mount_rot = m.rotation()
        self.hidden: frozenset[int] = frozenset()  # bodies not drawn (still in the physics)
        self.environment: SceneEnvironment = CLEAR  # what the image is seen through
        self._weather = CameraWeather(info)
        self._seed = seed

    def render(self, t: float, vehicle_origin: NDArray[np.float64],
               vehicle_rotation: NDArray[np.float64]) -> CameraFrame:
        """The image at time `t` for the vehicle frame's world pose: origin (3,) [m] and
        rotation (3, 3) (vehicle -> world)."""
        eye = vehicle_origin + vehicle_rotation @ self._mount_xyz
        axes = vehicle_rotation @ self._mount_rot  # columns: the camera's x, y, z in the world
        view = self._c.computeViewMatrix(eye.tolist(), (eye + axes[:, 0]).tolist(),
                                         axes[:, 2].tolist())
        info = self.info
        poses = [(b, *self._c.getBasePositionAndOrientation(b)) for b in sorted(self.hidden)]
        for body, _, _ in poses:  # out of sight for this frame only (a draw reads no contacts)
            self._c.resetBasePositionAndOrientation(body, AWAY, (0.0, 0.0, 0.0, 1.0))
        with quiet_c_output():  # the EGL plugin reports its GL vendor on the first frame
            _, _, rgba, depth, _ = self._c.getCameraImage(
                info.width, info.height, view, self._projection, renderer=self._renderer,
                flags=pybullet.ER_NO_SEGMENTATION_MASK, shadow=0,
            )
        for body, position, quat in poses:
            self._c.resetBasePositionAndOrientation(body, position, quat)
        rgba = np.asarray(rgba, dtype=np.uint8).reshape(info.height, info.width, 4)
        # OpenCV drops the alpha in one vectorised pass, 25x faster than numpy's strided copy
        rgb = np.asarray(cv2.cvtColor(rgba, cv2.COLOR_RGBA2RGB), dtype=np.uint8)
        if self.environment is not CLEAR:
            buffer = np.asarray(depth, dtype=np.float32).reshape(info.height, info.width)
            rgb = self._weather.apply(rgb, buffer, self.environment,
                                      (*self._seed, frame_key(t)))
        return CameraFrame(t=t, info=info, rgb=rgb)


@dataclass(frozen=True, slots=True, eq=False)
class CameraSensor:
    """A `Camera` on the car: captures a frame from the ego's true pose."""

    camera: Camera
    timing: SensorTiming  # its entry in the rates table
    ride_height: float  # [m] the base link's origin above the vehicle frame's (the ground)

    @property
    def name(self) -> str:
        return self.camera.info.name

    @property
    def rate(self) -> Rate:
        return self.timing.rate

    @property
    def latency(self) -> float:
        return self.timing.latency

    def capture(self, t: float, ego: EgoTruth) -> Reading:
        return Reading(self.name, self.camera.render(t, *vehicle_pose(ego, self.ride_height)))
