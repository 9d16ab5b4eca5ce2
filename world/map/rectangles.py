"""Rectangles on the ground plane (a body's or a building's footprint) and whether two
overlap: the separating-axis test, whose candidate axes for two rectangles are their four
edge normals; two rectangles overlap where their projections overlap on all four. Touching
edges do not overlap (no area is shared) unless asked (`touching`: a distance of 0)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

Corners = NDArray[np.float64]  # (4, 2) [m], in order around the rectangle


def rectangle(cx: float, cy: float, heading: float, length: float, width: float) -> Corners:
    """The corners of a rectangle centred at (cx, cy), its length along `heading`."""
    c, s = math.cos(heading), math.sin(heading)
    u = np.array([c, s]) * length / 2.0
    v = np.array([-s, c]) * width / 2.0
    centre = np.array([cx, cy])
    return np.array([centre + u + v, centre - u + v, centre - u - v, centre + u - v])


def overlap(a: Corners, b: Corners, *, touching: bool = False) -> bool:
    """Whether rectangles `a` and `b` share area (no edge normal of either separates them);
    with `touching`, also whether they only touch (a distance of exactly 0)."""
    for poly in (a, b):
        for k in range(4):
            edge = poly[(k + 1) % 4] - poly[k]
            axis = np.array([-edge[1], edge[0]])
            pa, pb = a @ axis, b @ axis
            gap = max(pb.min() - pa.max(), pa.min() - pb.max())
            if gap > 0.0 or (gap == 0.0 and not touching):
                return False
    return True
