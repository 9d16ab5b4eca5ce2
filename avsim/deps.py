"""Make the heavy native dependencies importable on a fresh machine.

Open3D's libusb dependency is handled in `world.frames.import_open3d` (the one place that
imports Open3D); `check()` imports every native dependency once, for `make setup`.
"""

from __future__ import annotations

import importlib

from world.frames import import_open3d


def check() -> None:
    """Import every native dependency once (run by `make setup`)."""
    o3d = import_open3d()
    for name in ("pybullet", "cv2", "rerun", "filterpy.kalman", "scipy.optimize"):
        importlib.import_module(name)
    print(f"native dependencies ok (open3d {o3d.__version__})")
