"""The road surface as textured triangle meshes, with the lane markings painted in the texture.

Pure data (numpy, no PyBullet): the world builder turns each `TexturedMesh` into a visual
shape. The surface lies flat `SURFACE_Z` above the ground, in the map frame. The texture of
a cross-section is one dash period of the paved road:

- across (u, texture columns): u = 0 at the right paved edge (the shoulder's outer edge),
  u = 1 at the left paved edge (the outermost lane's left edge);
- along (v, texture rows): v = (s mod DASH_PERIOD) / DASH_PERIOD; row i covers
  v in [i / H, (i + 1) / H), and the dashes are painted at v in [0, DASH_LENGTH / DASH_PERIOD).

The surface is a strip with two vertices across (right and left paved edge) per station:
the texture carries every marking, so the strip needs no more. A segment whose lane widths
change along it (a `LaneProfile`) is textured as its uniform `canonical` section (lanes
`PROFILE_LANE` wide, a shoulder `PROFILE_SHOULDER` wide where it has one), and its strip
has a vertex across at every lane boundary and at both edges of every painted line: the
texture's columns between those cuts stretch to where the boundaries are at each station,
while each line keeps its width and its place on its boundary (its offset from the
boundary nearest to it in the canonical section), so the camera sees the lines where the
map has them. Stations are at most
`MAX_STEP` apart (closer on tight arcs, for a chord error below `MAX_CHORD_ERROR` at the
outer edge) and include every multiple of `DASH_PERIOD`, where the strip's vertices are
duplicated (v = 1 ending one period, v = 0 starting the next) so that v never wraps
inside a quad.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from world.hdmap import CrossSection, LineMark, LinePaint, MarkKind, PaintColour, RoadMap

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]
ImageRGB = NDArray[np.uint8]

# -- markings -----------------------------------------------------------------------------
LINE_WIDTH = 0.15  # [m] white edge and lane lines
DASH_LENGTH = 3.0  # [m] painted part of a dashed line
DASH_PERIOD = 12.0  # [m] dash + gap
CENTRE_LINE_WIDTH = 0.12  # [m] each of the two yellow centre lines
CENTRE_LINE_GAP = 0.12  # [m] between the two yellow centre lines
EDGE_LINE_INSET = 0.10  # [m] least distance from a paved edge to an edge line's centre

# -- texture ------------------------------------------------------------------------------
TEXEL_ACROSS = 0.025  # [m/px] texture resolution across the road
TEXEL_ALONG = 0.05  # [m/px] texture resolution along the road
ASPHALT_RGB = (58.0, 58.0, 61.0)  # [0..255]
SHOULDER_RGB = (74.0, 72.0, 68.0)  # [0..255] a lighter, older paved shoulder
WHITE_RGB = (232.0, 232.0, 226.0)  # [0..255]
YELLOW_RGB = (228.0, 176.0, 32.0)  # [0..255]
ASPHALT_NOISE = 5.0  # [0..255] 1-sigma per-texel brightness noise
TEXTURE_SEED = 20240  # [-] fixed: the same cross-section always gives the same texture

# -- tessellation -------------------------------------------------------------------------
SURFACE_Z = 0.005  # [m] just above the ground plane
MAX_STEP = 2.0  # [m] station spacing of the strip
MAX_CHORD_ERROR = 0.02  # [m] at the outermost paved edge on arcs
MAX_MESH_VERTICES = 4000  # [-] per mesh (PyBullet's mesh size limit)
STATION_TOL = 1e-6  # [m] a period boundary this close to a segment's end is not split at

PROFILE_LANE = 3.5  # [m] a canonical lane's width (the texture of a varying section)
PROFILE_SHOULDER = 2.5  # [m] a canonical shoulder's width

TextureKey = tuple[int, int, float, float, LinePaint | None]  # lanes, oncoming lanes, lane
#   width, shoulder, the map file's paint


@dataclass(frozen=True, eq=False)
class TexturedMesh:
    """A triangle mesh with one texture. Arrays are in the map frame (z up)."""

    name: str
    vertices: FloatArray  # (N, 3) [m] map frame
    indices: NDArray[np.int32]  # (M, 3) counter-clockwise seen from above
    uvs: FloatArray  # (N, 2) [-] texture coordinates in [0, 1]
    normals: FloatArray  # (N, 3) unit, +z
    texture: ImageRGB  # (H, W, 3) uint8 RGB; row 0 is v = 0, column 0 is u = 0


@dataclass(frozen=True, slots=True)
class Marking:
    """One painted line of a cross-section, across from the right paved edge."""

    centre: float  # [m] from the right paved edge (u = centre / paved width)
    width: float  # [m]
    dashed: bool  # painted on v in [0, DASH_LENGTH / DASH_PERIOD) only
    rgb: tuple[float, float, float]  # [0..255]


def texture_key(section: CrossSection) -> TextureKey:
    """What a cross-section's texture depends on (not its zone; a varying section's is its
    `canonical` one's)."""
    c = canonical(section)
    return c.lanes, c.oncoming_lanes, c.lane_width, c.shoulder, c.paint


def canonical(section: CrossSection) -> CrossSection:
    """The uniform section that textures `section`: itself if it has no lane profile, else
    its lanes `PROFILE_LANE` wide and a shoulder `PROFILE_SHOULDER` wide if its shoulder
    is ever wider than 0 on it (module doc)."""
    if section.profile is None:
        return section
    bounds = np.asarray(section.profile.boundaries)
    shoulder = PROFILE_SHOULDER if np.any(bounds[1] != bounds[0]) else 0.0
    return CrossSection(section.lanes, section.oncoming_lanes, PROFILE_LANE, shoulder,
                        section.zone, section.paint)


def markings(section: CrossSection) -> list[Marking]:
    """The painted lines of a cross-section, right to left.

    White solid at the right edge of lane 0 (the shoulder boundary), white dashed between
    ego lanes, double yellow at the centre line (when there are oncoming lanes), white
    dashed between oncoming lanes, white solid at the left paved edge. Lines are centred on
    their lane boundary, except that an edge line keeps `EDGE_LINE_INSET` from a paved edge.
    A varying section's are its `canonical` section's (the texture's).
    """
    section = canonical(section)
    if section.paint is not None:
        return file_markings(section, section.paint)
    w, shoulder, width = section.lane_width, section.shoulder, section.paved_width
    lines = [Marking(max(shoulder, EDGE_LINE_INSET), LINE_WIDTH, False, WHITE_RGB)]
    lines += [
        Marking(shoulder + i * w, LINE_WIDTH, True, WHITE_RGB) for i in range(1, section.lanes)
    ]
    centre = shoulder + section.lanes * w
    if section.oncoming_lanes > 0:
        half_pitch = 0.5 * (CENTRE_LINE_WIDTH + CENTRE_LINE_GAP)
        lines += [
            Marking(centre - half_pitch, CENTRE_LINE_WIDTH, False, YELLOW_RGB),
            Marking(centre + half_pitch, CENTRE_LINE_WIDTH, False, YELLOW_RGB),
        ]
        lines += [
            Marking(centre + j * w, LINE_WIDTH, True, WHITE_RGB)
            for j in range(1, section.oncoming_lanes)
        ]
    lines.append(Marking(width - EDGE_LINE_INSET, LINE_WIDTH, False, WHITE_RGB))
    return lines


def file_markings(section: CrossSection, paint: LinePaint) -> list[Marking]:
    """The painted lines of a section whose map file paints them (OpenDRIVE road marks),
    right to left: each centred on its lane boundary, an edge line kept `EDGE_LINE_INSET`
    plus half its width from a paved edge; unpainted boundaries (`MarkKind.NONE`) left out."""
    w, shoulder, width = section.lane_width, section.shoulder, section.paved_width
    bounds = [shoulder + i * w for i in range(section.lanes + 1 + len(paint.oncoming))]
    marks = [paint.right_edge, *paint.lane_lines, paint.left_edge, *paint.oncoming]
    lines = []
    for centre, mark in zip(bounds, marks, strict=True):
        if mark.kind is MarkKind.NONE:
            continue
        inset = EDGE_LINE_INSET + 0.5 * mark.width
        lines.append(Marking(min(max(centre, inset), width - inset), mark.width,
                             mark.kind is MarkKind.BROKEN, _rgb(mark)))
    return lines


def _rgb(mark: LineMark) -> tuple[float, float, float]:
    return YELLOW_RGB if mark.colour is PaintColour.YELLOW else WHITE_RGB


def _coverage(lo: float, hi: float, n: int, extent: float) -> FloatArray:
    """[-] fraction of each of n texels spanning [0, extent] that [lo, hi] covers, (n,)."""
    edges = np.linspace(0.0, extent, n + 1)
    overlap = np.minimum(edges[1:], hi) - np.maximum(edges[:-1], lo)
    return np.clip(overlap / (extent / n), 0.0, 1.0)


def make_road_texture(section: CrossSection) -> ImageRGB:
    """(H, W, 3) uint8 RGB texture of one dash period of the cross-section (its
    `canonical` one's).

    W = paved width / TEXEL_ACROSS columns (u = 0 at the right paved edge), H =
    DASH_PERIOD / TEXEL_ALONG rows. Asphalt with deterministic noise, the shoulder a little
    lighter, then each marking blended in by its area coverage of each texel.
    """
    section = canonical(section)
    width = section.paved_width
    cols = max(1, round(width / TEXEL_ACROSS))
    rows = max(1, round(DASH_PERIOD / TEXEL_ALONG))
    rng = np.random.default_rng(TEXTURE_SEED)
    shoulder = _coverage(0.0, section.shoulder, cols, width)[None, :, None]
    base = np.asarray(ASPHALT_RGB) * (1.0 - shoulder) + np.asarray(SHOULDER_RGB) * shoulder
    noise = rng.normal(0.0, ASPHALT_NOISE, size=(rows, cols, 1))
    image = np.broadcast_to(base, (rows, cols, 3)) + noise
    solid = np.ones(rows)
    dash = _coverage(0.0, DASH_LENGTH, rows, DASH_PERIOD)
    for m in markings(section):
        across = _coverage(m.centre - 0.5 * m.width, m.centre + 0.5 * m.width, cols, width)
        alpha = np.outer(dash if m.dashed else solid, across)[:, :, None]
        image = image * (1.0 - alpha) + np.asarray(m.rgb) * alpha
    return np.clip(np.rint(image), 0, 255).astype(np.uint8)


def _max_step(road_map: RoadMap, piece_index: int) -> float:
    """[m] station spacing on a piece: MAX_STEP, or less on an arc so that the chord error
    at the paved edge farthest from the arc's centre stays below MAX_CHORD_ERROR."""
    piece = road_map.pieces[piece_index]
    k = piece.curvature
    if k == 0.0:
        return MAX_STEP
    c = road_map.sections[piece_index]
    if c.profile is None:
        right, left = c.right_edge, c.left_edge
    else:  # the edges farthest out along the segment
        edges = road_map.segment_boundaries(
            piece_index, np.linspace(piece.s0, piece.s0 + piece.length, 33))
        right, left = float(edges[:, 0].min()), float(edges[:, -1].max())
    outer = max(abs(1.0 / k - right), abs(1.0 / k - left))  # [m] radius
    dtheta = 2.0 * math.acos(max(-1.0, 1.0 - MAX_CHORD_ERROR / outer))
    return min(MAX_STEP, dtheta / abs(k))


def _runs(s_start: float, s_end: float, step: float) -> list[FloatArray]:
    """Station arrays covering [s_start, s_end], split at multiples of DASH_PERIOD, each
    evenly spaced with gaps <= step."""
    first = math.floor(s_start / DASH_PERIOD) + 1
    cuts = [n * DASH_PERIOD for n in range(first, math.ceil(s_end / DASH_PERIOD))]
    inner = [c for c in cuts if s_start + STATION_TOL < c < s_end - STATION_TOL]
    return [
        np.linspace(a, b, max(1, math.ceil((b - a) / step - STATION_TOL)) + 1)
        for a, b in itertools.pairwise([s_start, *inner, s_end])
    ]


@dataclass
class _MeshBuffer:
    """Strips of one texture, collected until a mesh is full, and the meshes made so far."""

    key_index: int
    texture: ImageRGB
    xy: list[FloatArray] = field(default_factory=list)
    uv: list[FloatArray] = field(default_factory=list)
    cols: list[int] = field(default_factory=list)  # vertices across, per strip
    count: int = 0  # vertices in xy
    meshes: list[TexturedMesh] = field(default_factory=list)

    def add(self, xy: FloatArray, uv: FloatArray, cols: int = 2) -> None:
        """Collect one strip (`cols` vertices across per station), first flushing if it
        would overfill the mesh."""
        if self.count + len(xy) > MAX_MESH_VERTICES:
            self.flush()
        self.xy.append(xy)
        self.uv.append(uv)
        self.cols.append(cols)
        self.count += len(xy)

    def flush(self) -> None:
        """Turn the collected strips into one mesh."""
        if not self.xy:
            return
        indices, base = [], 0
        for xy, cols in zip(self.xy, self.cols, strict=True):
            indices.append(_strip_indices(len(xy) // 2, base) if cols == 2
                           else _grid_indices(len(xy) // cols, cols, base))
            base += len(xy)
        xy_all = np.concatenate(self.xy)
        vertices = np.column_stack([xy_all, np.full(len(xy_all), SURFACE_Z)])
        normals = np.zeros_like(vertices)
        normals[:, 2] = 1.0
        mesh = TexturedMesh(
            name=f"road_surface_{self.key_index}_{len(self.meshes)}",
            vertices=vertices,
            indices=np.concatenate(indices),
            uvs=np.concatenate(self.uv),
            normals=normals,
            texture=self.texture,
        )
        self.meshes.append(mesh)
        self.xy, self.uv, self.cols, self.count = [], [], [], 0


def _strip(road_map: RoadMap, piece_index: int, s: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(xy (2n, 2), uv (2n, 2)) of a strip at stations s (n,) within one dash period,
    vertices interleaved right edge, left edge."""
    c = road_map.sections[piece_index]
    right = road_map.position(s, np.full_like(s, c.right_edge))
    left = road_map.position(s, np.full_like(s, c.left_edge))
    period = math.floor(0.5 * (s[0] + s[-1]) / DASH_PERIOD)
    v = np.clip(s / DASH_PERIOD - period, 0.0, 1.0)
    xy = np.stack([right, left], axis=1).reshape(-1, 2)
    uv = np.stack([np.zeros_like(v), v, np.ones_like(v), v], axis=1).reshape(-1, 2)
    return xy, uv


def _cuts(section: CrossSection) -> tuple[FloatArray, IntArray, FloatArray]:
    """Where a varying section's strip is cut across, in its `canonical` section: ([m]
    each cut from the right paved edge, sorted; the boundary (`RoadMap.lane_boundaries`
    index) each cut keeps its offset from; [m] that offset): every boundary (offset 0) and
    both edges of every painted line (module doc)."""
    c = canonical(section)
    bounds = c.boundary_cubics()[:, 0]
    bounds = bounds - bounds[0]
    cut, ref = list(bounds), list(range(len(bounds)))
    for m in markings(c):
        k = int(np.argmin(np.abs(bounds - m.centre)))
        for edge in (m.centre - 0.5 * m.width, m.centre + 0.5 * m.width):
            cut.append(edge)
            ref.append(k)
    order = np.argsort(cut, kind="stable")
    cuts = np.asarray(cut)[order]
    refs = np.asarray(ref, dtype=np.intp)[order]
    return cuts, refs, cuts - bounds[refs]


def _profiled_strip(road_map: RoadMap, piece_index: int,
                    s: FloatArray) -> tuple[FloatArray, FloatArray, int]:
    """(xy (n m, 2), uv (n m, 2), m) of a varying section's strip at stations s (n,) within
    one dash period: m vertices across per station at the `_cuts`, station-major."""
    section = road_map.sections[piece_index]
    cuts, refs, shift = _cuts(section)
    bounds = road_map.segment_boundaries(piece_index, s)  # (n, boundaries)
    d = bounds[:, refs] + shift  # (n, m) [m] offsets from the reference line
    d = np.clip(np.maximum.accumulate(d, axis=1), bounds[:, :1], bounds[:, -1:])
    n, m = d.shape
    xy = road_map.position(np.repeat(s, m), d.reshape(-1))
    period = math.floor(0.5 * (s[0] + s[-1]) / DASH_PERIOD)
    v = np.clip(s / DASH_PERIOD - period, 0.0, 1.0)
    u = cuts / canonical(section).paved_width
    uv = np.stack([np.broadcast_to(u, (n, m)), np.broadcast_to(v[:, None], (n, m))], axis=-1)
    return xy, uv.reshape(-1, 2), m


def _grid_indices(n_stations: int, cols: int, base: int) -> NDArray[np.int32]:
    """(2 (n - 1) (cols - 1), 3) triangles of a station-major grid of n stations by `cols`
    vertices across (right to left) whose first vertex is `base`."""
    i, j = np.meshgrid(np.arange(n_stations - 1), np.arange(cols - 1), indexing="ij")
    a = base + i * cols + j
    b, c = a + 1, a + cols
    d = c + 1
    tris = np.stack([np.stack([a, c, d], -1), np.stack([a, d, b], -1)], axis=-2)
    return tris.reshape(-1, 3).astype(np.int32)


def _strip_indices(n_stations: int, base: int) -> NDArray[np.int32]:
    """(2 (n - 1), 3) triangles of a strip of n stations whose first vertex is `base`."""
    i = base + 2 * np.arange(n_stations - 1)
    r0, l0, r1, l1 = i, i + 1, i + 2, i + 3
    tris = np.stack([np.stack([r0, r1, l1], 1), np.stack([r0, l1, l0], 1)], axis=1)
    return tris.reshape(-1, 3).astype(np.int32)


def build_road_surface(road_map: RoadMap) -> list[TexturedMesh]:
    """The paved road (shoulder included) as textured meshes, <= MAX_MESH_VERTICES each.

    One texture per distinct cross-section (lanes, oncoming lanes, lane width, shoulder),
    shared (the same array object) by every mesh of segments with that cross-section.
    Meshes are ordered by the first appearance of their cross-section along the route.
    """
    buffers: dict[TextureKey, _MeshBuffer] = {}
    for i, piece in enumerate(road_map.pieces):
        section = road_map.sections[i]
        key = texture_key(section)
        if key not in buffers:
            buffers[key] = _MeshBuffer(len(buffers), make_road_texture(section))
        for s in _runs(piece.s0, piece.s0 + piece.length, _max_step(road_map, i)):
            if section.profile is None:
                buffers[key].add(*_strip(road_map, i, s))
            else:
                buffers[key].add(*_profiled_strip(road_map, i, s))
    meshes: list[TexturedMesh] = []
    for buf in buffers.values():
        buf.flush()
        meshes += buf.meshes
    return meshes


THROUGH_LENGTH = 400.0  # [m] how far a road left by an exit is drawn on from its fork
THROUGH_DROP = 0.003  # [m] it lies this much below the route's surface (no z-fighting)


def build_through_roads(road_map: RoadMap, length: float = THROUGH_LENGTH) -> list[TexturedMesh]:
    """The roads the route leaves by its exits, straight on from each fork (scenery)."""
    meshes: list[TexturedMesh] = []
    for k, exit_ in enumerate(road_map.exits):
        for mesh in build_road_surface(road_map.through_road(exit_, length)):
            lowered = mesh.vertices - np.array([0.0, 0.0, THROUGH_DROP])
            meshes.append(replace(mesh, name=f"through{k}_{mesh.name}", vertices=lowered))
    return meshes
