"""Which renderer draws the cameras: EGL through Mesa when it loads, else TinyRenderer.

The EGL plugin must be loaded into a client BEFORE the scene is built (frames come back
empty otherwise), so `attach_renderer` is called right after the client is made. The choice
is automatic: EGL when `eglRenderer` loads and draws a test frame, TinyRenderer otherwise;
``AVSIM_RENDERER=tiny`` forces TinyRenderer. The plugin prints its GL banner on the C
stdout; it is silenced (the choice is reported by the caller instead).

Shadows. The EGL plugin ignores `getCameraImage`'s ``shadow=0``: its renderer draws a
4096 x 4096 shadow map before every frame, whatever the frame's size (about 40 ms on llvmpipe,
two thirds of a 640 x 480 frame). The switch is a file-local global of the plugin,
``useShadowMap`` in Bullet's ``GLInstancingRenderer.cpp``, with no API. `attach_renderer`
finds it in the plugin's ELF symbol table (pyelftools), checks that it holds ``true`` and
clears it, so EGL draws what TinyRenderer draws with ``shadow=0``: direct lighting, no
shadows. Where the symbol cannot be found the plugin is not used (TinyRenderer instead), so
a run never renders shadows on one machine and none on another.
"""

from __future__ import annotations

import ctypes
import enum
import functools
import importlib.util
import os
from pathlib import Path

import numpy as np
import pybullet
from pybullet_utils.bullet_client import BulletClient

from world.core.quiet import quiet_c_output

_SHADOW_SWITCH = "useShadowMap"  # bool, GLInstancingRenderer.cpp (file-local, in .symtab)
_ANCHOR = "PyInit_eglRenderer"  # an exported function of the plugin: gives its load address


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
    spec = importlib.util.find_spec("eglRenderer")
    if spec is None or spec.origin is None:
        return Renderer.TINY
    with quiet_c_output():
        plugin = client.loadPlugin(spec.origin, "_eglRendererPlugin")
    if plugin < 0 or not switch_off_shadows(Path(spec.origin)) or not _draws(client):
        if plugin >= 0:
            client.unloadPlugin(plugin)
        return Renderer.TINY
    return Renderer.EGL


def switch_off_shadows(plugin: Path) -> bool:
    """Clear the loaded EGL plugin's shadow-map switch (see the module docstring); False when
    it cannot be found or does not hold a bool. The switch is the plugin's, shared by every
    client of the process, and back to ``true`` whenever the plugin is loaded afresh, so it
    is cleared at every attach."""
    switch = shadow_switch(plugin)
    if switch is None or switch.value not in (0, 1):
        return False
    switch.value = 0
    return True


def read_plugin_symbols() -> None:
    """Read the EGL plugin's symbol table now (it is read once per process): a process that
    forks workers does it once for all of them."""
    spec = importlib.util.find_spec("eglRenderer")
    if spec is not None and spec.origin is not None:
        _symbols(Path(spec.origin), (_SHADOW_SWITCH, _ANCHOR))


def shadow_switch(plugin: Path) -> ctypes.c_uint8 | None:
    """The loaded EGL plugin's ``useShadowMap`` (a C++ bool: one byte), or None when its
    symbols cannot be found (a stripped or different build)."""
    symbols = _symbols(plugin, (_SHADOW_SWITCH, _ANCHOR))
    if symbols is None:
        return None
    try:
        library = ctypes.CDLL(str(plugin), mode=os.RTLD_NOLOAD | os.RTLD_LAZY)  # if loaded
    except OSError:
        return None
    anchor = ctypes.cast(getattr(library, _ANCHOR), ctypes.c_void_p).value
    if anchor is None:
        return None
    return ctypes.c_uint8.from_address(anchor - symbols[_ANCHOR] + symbols[_SHADOW_SWITCH])


@functools.cache
def _symbols(library: Path, names: tuple[str, ...]) -> dict[str, int] | None:
    """The link-time addresses of `names` in the ELF file's symbol table, or None when one is
    missing (a stripped or different build)."""
    from elftools.elf.elffile import ELFFile  # only where the EGL plugin is tried
    from elftools.elf.sections import SymbolTableSection

    with library.open("rb") as f:
        table = ELFFile(f).get_section_by_name(".symtab")
        if not isinstance(table, SymbolTableSection):
            return None
        found: dict[str, int] = {}
        for name in names:
            symbol = table.get_symbol_by_name(name)
            if not symbol:
                return None
            found[name] = int(symbol[0]["st_value"])
    return found


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
