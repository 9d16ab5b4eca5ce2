"""Make the heavy native dependencies importable on a fresh machine.

Open3D 0.20 links against `libusb-1.0.so.0`, which a fresh Debian machine lacks. The Makefile
installs Debian's `libusb-1.0-0` when it can (root, apt); otherwise the `libusb-package`
wheel's copy (its SONAME is `libusb-1.0.so.0`) is loaded globally before Open3D, which
satisfies the dynamic linker. `import_open3d()` is the one place that imports Open3D.
"""

from __future__ import annotations

import ctypes
import importlib
from types import ModuleType


def preload_libusb() -> None:
    """Load a libusb-1.0 into the process so that Open3D's dependency resolves."""
    try:
        ctypes.CDLL("libusb-1.0.so.0", mode=ctypes.RTLD_GLOBAL)
        return
    except OSError:
        pass
    import libusb_package

    path = libusb_package.get_library_path()
    if path is None:
        raise ImportError("no libusb-1.0 found (install libusb-1.0-0 or libusb-package)")
    ctypes.CDLL(str(path), mode=ctypes.RTLD_GLOBAL)


def import_open3d() -> ModuleType:
    preload_libusb()
    return importlib.import_module("open3d")


def check() -> None:
    """Import every native dependency once (run by `make setup`)."""
    o3d = import_open3d()
    for name in ("pybullet", "cv2", "rerun", "filterpy.kalman", "scipy.optimize"):
        importlib.import_module(name)
    print(f"native dependencies ok (open3d {o3d.__version__})")
