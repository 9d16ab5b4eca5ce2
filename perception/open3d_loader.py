"""The one place that imports Open3D, after making its native dependency loadable.

Open3D 0.20 links against `libusb-1.0.so.0`, which a fresh Debian machine lacks. The pinned
`libusb-package` wheel carries a copy whose SONAME is `libusb-1.0.so.0`; loading it globally
before Open3D satisfies the dynamic linker (a system libusb, when present, is used instead).
"""

from __future__ import annotations

import ctypes
import functools
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


@functools.cache
def import_open3d() -> ModuleType:
    """The open3d module, imported once, with its log quiet below errors."""
    preload_libusb()
    o3d = importlib.import_module("open3d")
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    return o3d
