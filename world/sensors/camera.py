"""Cameras: a pinhole `CameraInfo` rendered from the car's true pose by PyBullet.

The camera's world pose is the body's pose (from the physics, pitch and roll included)
composed with the mount; the view matrix looks along the mount's x axis with its z axis up,
and the projection has the camera's vertical field of view and aspect. Lighting is Bullet's
default (no shadows: they triple TinyRenderer's cost and add nothing the lane finder needs).
"""

from __future__ import annotations

import math

import numpy as np
import pybullet
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from world.core.quiet import quiet_c_output
from world.core.rendering import Renderer
from world.frames import CameraFrame, CameraInfo


class Camera:
    """Renders one `CameraInfo` in one client."""

    def __init__(self, client: BulletClient, info: CameraInfo, renderer: Renderer) -> None:
        self.info = info
        self._c = client
        self._renderer = renderer.flag
        self._projection = client.computeProjectionMatrixFOV(
            math.degrees(info.fov_y), info.width / info.height, info.near, info.far
        )
        m = info.mount
        self._mount_xyz = np.array([m.x, m.y, m.z])  # [m] vehicle frame
        self._mount_rot = m.rotation()

    def render(self, t: float, vehicle_origin: NDArray[np.float64],
               vehicle_rotation: NDArray[np.float64]) -> CameraFrame:
        """The image at time `t` for the vehicle frame's world pose: origin (3,) [m] and
        rotation (3, 3) (vehicle -> world)."""
        eye = vehicle_origin + vehicle_rotation @ self._mount_xyz
        axes = vehicle_rotation @ self._mount_rot  # columns: the camera's x, y, z in the world
        view = self._c.computeViewMatrix(eye.tolist(), (eye + axes[:, 0]).tolist(),
                                         axes[:, 2].tolist())
        info = self.info
        with quiet_c_output():  # the EGL plugin reports its GL vendor on the first frame
            _, _, rgba, _, _ = self._c.getCameraImage(
                info.width, info.height, view, self._projection, renderer=self._renderer,
                flags=pybullet.ER_NO_SEGMENTATION_MASK, shadow=0,
            )
        rgb = np.asarray(rgba, dtype=np.uint8).reshape(info.height, info.width, 4)[..., :3]
        return CameraFrame(t=t, info=info, rgb=np.ascontiguousarray(rgb))
