"""Painted road marks at features: stop lines and zebra crosswalks, as decal meshes.

Pure data (numpy, no PyBullet), like `world.scene.road_mesh`: each mark is a `TexturedMesh` of thin
quads lying `MARK_Z` above the ground, just over the road surface (`road_mesh.SURFACE_Z`), with
a plain white texture. The world builder loads them through the same OBJ + MTL path as the
road surface (the EGL renderer drops meshes given as vertex arrays). Marks follow the road:
each quad is split along the route every `MARK_STEP` metres at most, so they bend with arcs.

Across, offsets d are from the route's reference line (left +):

- stop line: stations [s, s + STOP_LINE_WIDTH] (its near edge on the stop line's station
  s), across the ego-direction lanes, from lane 0's right edge to the centre line (the left
  edge of the ego's lanes);
- crosswalk: stations [s, s + width], bars `ZEBRA_BAR` wide with `ZEBRA_GAP` between them,
  running along the route, across the whole paved road (shoulder included); as many bars as
  fit, the pattern centred on the paved width.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from world.hdmap import Crosswalk, RoadMap, StopSign
from world.scene.road_mesh import TexturedMesh

FloatArray = NDArray[np.float64]

MARK_Z = 0.008  # [m] decal height above the ground, over `road_mesh.SURFACE_Z`
MARK_STEP = 1.0  # [m] largest station spacing of a mark's quads
STOP_LINE_WIDTH = 0.3  # [m] a stop line's extent along the route
ZEBRA_BAR = 0.5  # [m] a zebra bar's width, across the road
ZEBRA_GAP = 0.5  # [m] across the road, between bars
PAINT_RGB = (232, 232, 226)  # [0..255] as the road's white lines (`road_mesh.WHITE_RGB`)
PAINT_TEXELS = 4  # [px] side of the plain paint texture


def paint_texture() -> NDArray[np.uint8]:
    """(PAINT_TEXELS, PAINT_TEXELS, 3) uint8 plain white paint."""
    return np.full((PAINT_TEXELS, PAINT_TEXELS, 3), PAINT_RGB, dtype=np.uint8)


def stop_line_band(road_map: RoadMap, s: float) -> tuple[float, float]:
    """([m] right, [m] left) offsets of a stop line at station s: lane 0's right edge and the
    centre line (the ego's lanes)."""
    bounds = road_map.lane_boundaries(s)
    return float(bounds[1]), float(bounds[road_map.cross_section_at(s).lanes + 1])


def zebra_bars(road_map: RoadMap, s: float) -> list[tuple[float, float]]:
    """([m] right, [m] left) offsets of each zebra bar at station s, right to left: as many
    ZEBRA_BAR bars with ZEBRA_GAP gaps as fit between the paved edges, centred."""
    right, left = (float(x) for x in road_map.paved_edges(s))
    width = left - right
    n = max(1, math.floor((width + ZEBRA_GAP) / (ZEBRA_BAR + ZEBRA_GAP)))
    margin = 0.5 * (width - n * ZEBRA_BAR - (n - 1) * ZEBRA_GAP)
    starts = right + margin + np.arange(n) * (ZEBRA_BAR + ZEBRA_GAP)
    return [(float(a), float(a + ZEBRA_BAR)) for a in starts]


def _quad_strip(road_map: RoadMap, s0: float, s1: float, d0: float,
                d1: float) -> tuple[FloatArray, FloatArray, NDArray[np.int32]]:
    """(xyz (2n, 3), uv (2n, 2), triangles (2 (n - 1), 3)) of a band [s0, s1] x [d0, d1]
    split along the route every MARK_STEP at most; counter-clockwise seen from above."""
    n = max(2, math.ceil((s1 - s0) / MARK_STEP) + 1)
    s = np.linspace(s0, s1, n)
    right = road_map.position(s, np.full(n, d0))
    left = road_map.position(s, np.full(n, d1))
    xy = np.stack([right, left], axis=1).reshape(-1, 2)
    xyz = np.column_stack([xy, np.full(len(xy), MARK_Z)])
    v = (s - s0) / (s1 - s0)
    uv = np.stack([np.zeros(n), v, np.ones(n), v], axis=1).reshape(-1, 2)
    i = 2 * np.arange(n - 1)
    r0, l0, r1, l1 = i, i + 1, i + 2, i + 3
    tris = np.stack([np.stack([r0, r1, l1], 1), np.stack([r0, l1, l0], 1)], axis=1)
    return xyz, uv, tris.reshape(-1, 3).astype(np.int32)


def _mesh(name: str, road_map: RoadMap, s0: float, s1: float,
          bands: list[tuple[float, float]]) -> TexturedMesh:
    """One white mesh of the bands [s0, s1] x [d0, d1]."""
    xyz, uv, tris = [], [], []
    base = 0
    for d0, d1 in bands:
        v, t, f = _quad_strip(road_map, s0, s1, d0, d1)
        xyz.append(v)
        uv.append(t)
        tris.append(f + base)
        base += len(v)
    vertices = np.concatenate(xyz)
    normals = np.zeros_like(vertices)
    normals[:, 2] = 1.0
    return TexturedMesh(name=name, vertices=vertices, indices=np.concatenate(tris),
                        uvs=np.concatenate(uv), normals=normals, texture=paint_texture())


def stop_line_mesh(road_map: RoadMap, stop: StopSign, index: int = 0) -> TexturedMesh:
    """The white stop line of `stop`: stations [s, s + STOP_LINE_WIDTH] across the ego's
    lanes (`stop_line_band`); named `stop_line_<index>`."""
    return _mesh(f"stop_line_{index}", road_map, stop.s, stop.s + STOP_LINE_WIDTH,
                 [stop_line_band(road_map, stop.s)])


def crosswalk_mesh(road_map: RoadMap, crosswalk: Crosswalk, index: int = 0) -> TexturedMesh:
    """The zebra bars of `crosswalk` (`zebra_bars` at its near edge) from s to s + width;
    named `crosswalk_<index>`."""
    s0 = crosswalk.s
    return _mesh(f"crosswalk_{index}", road_map, s0, s0 + crosswalk.width,
                 zebra_bars(road_map, s0))


def build_road_marks(road_map: RoadMap) -> list[TexturedMesh]:
    """Every stop line and crosswalk of the map, in station order, numbered per kind."""
    meshes: list[TexturedMesh] = []
    stops = crossings = 0
    for feature in road_map.features:
        if isinstance(feature, StopSign):
            meshes.append(stop_line_mesh(road_map, feature, stops))
            stops += 1
        elif isinstance(feature, Crosswalk):
            meshes.append(crosswalk_mesh(road_map, feature, crossings))
            crossings += 1
    return meshes
