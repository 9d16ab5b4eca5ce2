"""Which renderer draws the cameras: EGL through Mesa when it loads, else TinyRenderer.

The EGL plugin must be loaded into a client BEFORE the scene is built (frames come back
empty otherwise), so `attach_renderer` is called right after the client is made. The choice
is automatic: EGL when `eglRenderer` loads and draws a test frame, TinyRenderer otherwise;
``AVSIM_RENDERER=tiny`` forces TinyRenderer. The plugin prints its GL banner on the C
stdout; it is silenced (the choice is reported by the caller instead).
"""

from __future__ import annotations

import enum
import os
import pkgutil

import numpy as np
import pybullet
from pybullet_utils.bullet_client import BulletClient

from world.core.quiet import quiet_c_output


class Renderer(enum.Enum):
    EGL = "egl"  # OpenGL through EGL (Mesa llvmpipe on CPU): fixed cost per frame, scales well
    TINY = "tiny"  # Bullet's TinyRenderer on the CPU: cost grows with the pixel count

    @property
    def flag(self) -> int:
        """The `getCameraImage` renderer argument."""
        return int(pybullet.ER_BULLET_HARDWARE_OPENGL if self is Renderer.EGL
                   else pybullet.ER_TINY_RENDERER)


def attach_renderer(client: BulletClient) -> Renderer:
    """Load the EGL plugin into `client` if it works here; return the renderer to use."""
    if os.environ.get("AVSIM_RENDERER", "").lower() == "tiny":
        return Renderer.TINY
    loader = pkgutil.get_loader("eglRenderer")
    if loader is None:
        return Renderer.TINY
    with quiet_c_output():
        plugin = client.loadPlugin(loader.get_filename(), "_eglRendererPlugin")  # type: ignore[attr-defined]
    if plugin < 0 or not _draws(client):
        if plugin >= 0:
            client.unloadPlugin(plugin)
        return Renderer.TINY
    return Renderer.EGL


def _draws(client: BulletClient) -> bool:
    """A 16 x 16 test frame of a white box in front of the camera is not empty."""
    visual = client.createVisualShape(pybullet.GEOM_BOX, halfExtents=[1, 1, 1],
                                      rgbaColor=[1, 1, 1, 1])
    body = client.createMultiBody(0.0, -1, visual, [5.0, 0.0, 0.0], useMaximalCoordinates=True)
    view = client.computeViewMatrix([0, 0, 0], [1, 0, 0], [0, 0, 1])
    proj = client.computeProjectionMatrixFOV(60, 1.0, 0.1, 20.0)
    try:
        with quiet_c_output():
            img = client.getCameraImage(16, 16, view, proj, renderer=Renderer.EGL.flag,
                                        flags=pybullet.ER_NO_SEGMENTATION_MASK)
        rgba = np.asarray(img[2], dtype=np.uint8).reshape(16, 16, 4)
        return bool(rgba[..., :3].max() > 0)
    finally:
        client.removeBody(body)
