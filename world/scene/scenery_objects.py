"""Scenery objects (`world.spec.SceneryObjectSpec`: an OpenDRIVE file's road objects) as
collision parts and colours, for the world builder (no PyBullet here).

A box is a `Box`, a cylinder a `Cylinder`, an outline's prism a `ConvexHull` of its points;
the colour is its type's (`TYPE_RGB`, else `OTHER_RGB`).
"""

from __future__ import annotations

import numpy as np

from world.scene.collision import Box, ConvexHull, Cylinder, Shape
from world.spec import SceneryObjectSpec

TYPE_RGB: dict[str, tuple[float, float, float]] = {  # [-] 0..1
    "tree": (0.18, 0.40, 0.16),
    "vegetation": (0.25, 0.48, 0.20),
    "building": (0.62, 0.60, 0.56),
    "pole": (0.60, 0.60, 0.62),
    "streetLamp": (0.60, 0.60, 0.62),
    "railing": (0.70, 0.71, 0.72),
    "barrier": (0.70, 0.71, 0.72),
    "guardRail": (0.70, 0.71, 0.72),
    "obstacle": (0.85, 0.85, 0.82),
}
OTHER_RGB = (0.55, 0.52, 0.48)  # [-] any other type


def object_shape(obj: SceneryObjectSpec) -> Shape:
    """The collision shape of `obj` in its own frame (centred on `centre`, turned `yaw`)."""
    if obj.hull:
        return ConvexHull(np.array(obj.hull, dtype=float))
    if obj.round:
        return Cylinder(obj.half_extents[0], 2.0 * obj.half_extents[2])
    return Box(obj.half_extents)


def object_rgb(obj: SceneryObjectSpec) -> tuple[float, float, float]:
    """[-] 0..1 the colour of `obj`'s type."""
    return TYPE_RGB.get(obj.type, OTHER_RGB)
