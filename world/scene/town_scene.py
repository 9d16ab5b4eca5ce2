"""The static scenery of a grid town (`world.map.town`): streets, junctions, sidewalks, buildings.

Pure data (numpy, no PyBullet), like `world.scene.road_mesh`: the world builder turns the meshes
into visual bodies (OBJ + MTL files, as the EGL renderer needs), the pavements into static
bodies with collision, the buildings into boxes and the stop signs into poles with plates.
Everything is in the map (= town) frame; junction (ix, iy) stands at (ix, iy) * block.

- **Streets**: one straight strip per street from mouth to mouth, built by
  `road_mesh.build_road_surface` from a one-segment `RoadMap` (`street_road`: n lanes each
  way, no shoulder, `Zone.CITY`, its origin on lane 0 of the east / north direction at the
  west / south mouth), so the markings are a road's: a white solid edge line
  `EDGE_LINE_INSET` inside each kerb, white dashes between lanes of one direction (only
  with two or more lanes a direction), the double yellow centre line. (`markings` paints by
  the cross-section alone; a CITY zone gets exactly what any other zone gets.) The dashes
  start at each street's west / south mouth. The strips of all streets share one texture
  and are merged into meshes of at most `MAX_MESH_VERTICES`.
- **Junctions**: plain asphalt (`ASPHALT_RGB` with the road's texel noise), no markings,
  at the road's `SURFACE_Z`: the box, the arms' ends up to the mouths, and the rounded kerb
  corners where two streets meet (radius `layout.corner_radius`, centred `mouth` from the
  junction's centre on both axes). Where a street has no continuation, the kerb runs on
  straight (T-junctions) or meets the other at a square corner (the town's corners). One
  triangle fan from the centre per junction (the outline is star-shaped from it); it meets
  the street strips edge to edge at the mouths.
- **Stop lines**: a white `STOP_LINE_WIDTH` band across the lanes heading in (centre line to
  kerb) on every approach of `layout.approaches()`, its near edge on the approach's stop
  line (`STOP_SETBACK` before the mouth), `MARK_Z` high like the road's marks.
- **Pavements**: every block is one kerbed slab `KERB_HEIGHT` high, its outline the kerb (a
  rounded rectangle, convex): a `SIDEWALK_WIDTH` concrete ring along the kerb and around
  the corners (its inner edge the kerb moved `SIDEWALK_WIDTH` into the block: concentric
  arcs), the block's interior in `GROUND_RGB` (the ground plane's colour). Outside the town,
  four concrete strips `SIDEWALK_WIDTH` wide run along the outer kerbs (square corners).
  Each slab is one static body whose mesh (top and kerb faces) is also its collision shape,
  one per block plus four: the LiDAR's ray culling (`world.sensors.ray_culling`) works by
  bounding boxes, and one body for all kerbs would have a box holding the car, sending
  every downward ray to Bullet. Perception must not see the pavements: `KERB_HEIGHT` is
  below the LiDAR detector's ground clearance, so kerbs stay ground; `CONCRETE_RGB` is
  darker than the lane finder's white gate and far from the paint, and the sidewalk is far
  wider than a painted ridge.
- **Buildings**: a few axis-aligned `BuildingBox`es on each side of every block, their
  fronts `BUILDING_SETBACK` behind the sidewalk, walked along the side like
  `scenery.layout_buildings` (frontage, depth, height, facade, then a gap for
  `BUILDING_DENSITY`), dropped when they would leave the block's building zone or come
  within `MIN_BUILDING_GAP` of another; deterministic for the rng's state. Frontages
  (`BUILDING_FRONTAGE`) are longer than any object the LiDAR detector keeps, so a facade
  seen whole is not taken for one.
- **Stop signs**: a `StopSignPlacement` at every approach's `stop_sign` (its `s` is 0: not
  on a route).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from world.hdmap import RoadMap, Zone
from world.map.road import build_road_map
from world.map.town import HEADINGS, STOP_SETBACK, TownLayout
from world.scene.box_index import BoxIndex, Rect
from world.scene.road_marks import MARK_Z, STOP_LINE_WIDTH, paint_texture
from world.scene.road_mesh import (
    ASPHALT_NOISE,
    ASPHALT_RGB,
    MAX_MESH_VERTICES,
    SURFACE_Z,
    TEXTURE_SEED,
    TexturedMesh,
    build_road_surface,
)
from world.scene.scenery import (
    DEPTH_RANGE,
    GAP_JITTER,
    HEIGHT_RANGE,
    MIN_BUILDING_GAP,
    BuildingBox,
    StopSignPlacement,
    _facade,
)
from world.spec import RoadSpec, SegmentSpec

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int32]
Index = tuple[int, int]

SIDEWALK_WIDTH = 3.0  # [m] concrete from the kerb into the block
KERB_HEIGHT = 0.12  # [m] the sidewalk's top above the street (below the LiDAR detector's
#   `DetectorParams.ground_clearance`)
CONCRETE_RGB = (112, 110, 104)  # [0..255] sidewalk and kerb faces
GROUND_RGB = (84, 115, 64)  # [0..255] a block's interior: the ground plane's grass
CORNER_SEGMENTS = 12  # [-] chords per rounded kerb corner
JUNCTION_TEXEL = 0.1  # [m/px] the junction asphalt's texture
BUILDING_SETBACK = 4.0  # [m] from the sidewalk's inner edge to a building's front
BUILDING_FRONTAGE = (12.5, 30.0)  # [m] (min, max), the least over the LiDAR detector's
#   `DetectorParams.max_length`: a facade seen whole is no object to it
BUILDING_DENSITY = 0.7  # [-] built-up fraction of a block side's frontage
START_JITTER = 5.0  # [m] the first building of a side starts up to this far from its corner
INDEX_CELL = 50.0  # [m] cell of the placed buildings' index: a few buildings per cell
PAVEMENT_TEXELS = 8  # [px] per colour in the pavement's two-colour texture
_CONCRETE_UV = (0.25, 0.5)  # [-] the middle of the texture's concrete half ...
_GROUND_UV = (0.75, 0.5)  # [-] ... and of its ground half
_QUADRANTS = ("east", "north", "west", "south")  # quadrant k lies between these k and k + 1


@dataclass(frozen=True, slots=True, eq=False)
class Pavement:
    """A kerbed slab standing on the ground: a block's sidewalk and interior, or an outer
    sidewalk strip. Its collision is the prism of `outline` from z = 0 to `height`."""

    name: str  # the body's name: town_block_<bx>_<by>, town_edge_<side>
    outline: FloatArray  # (K, 2) [m] map frame, the kerb: a convex polygon, counter-clockwise
    height: float  # [m] its top above the ground
    mesh: TexturedMesh  # the top and the kerb faces (map frame)

    @property
    def centre(self) -> tuple[float, float]:
        """[m] the mean of the outline's corners (inside it: it is convex)."""
        x, y = self.outline.mean(axis=0)
        return float(x), float(y)


@dataclass(frozen=True, slots=True, eq=False)
class TownScene:
    """What `build_town_scene` lays out (module doc)."""

    streets: tuple[TexturedMesh, ...]  # street strips with their markings
    junctions: tuple[TexturedMesh, ...]  # plain asphalt
    stop_lines: tuple[TexturedMesh, ...]  # white bands
    pavements: tuple[Pavement, ...]  # blocks (row by row from the south-west), then 4 strips
    buildings: tuple[BuildingBox, ...]  # block by block, as `layout_town_buildings`
    stop_signs: tuple[StopSignPlacement, ...]  # in `approaches()` order

    @property
    def surfaces(self) -> tuple[TexturedMesh, ...]:
        """The visual-only meshes: streets, junctions, stop lines."""
        return (*self.streets, *self.junctions, *self.stop_lines)

    @property
    def meshes(self) -> tuple[TexturedMesh, ...]:
        """Every mesh (the surfaces, then the pavements'), for the recording."""
        return (*self.surfaces, *(p.mesh for p in self.pavements))


# -- geometry --------------------------------------------------------------------------------


def _axes(k: int) -> tuple[FloatArray, FloatArray]:
    """Unit vectors (u, v) of quadrant k: u along `_QUADRANTS[k]`, v along the next one."""
    a = 0.5 * math.pi * k
    u = np.array([math.cos(a), math.sin(a)])
    return u, np.array([-u[1], u[0]])


def corner_arc(layout: TownLayout, j: Index, k: int, inset: float = 0.0) -> FloatArray:
    """(CORNER_SEGMENTS + 1, 2) [m] the rounded kerb of quadrant k of junction j (k = 0:
    north-east, 1: north-west, 2: south-west, 3: south-east), counter-clockwise about the
    junction: from the street along `_QUADRANTS[k]` to the next one. `inset` > 0: the same
    corner of the outline moved `inset` into the block (a smaller concentric arc, a sharp
    corner once `inset` passes the radius)."""
    u, v = _axes(k)
    r = layout.corner_radius
    centre = np.array(layout.centre(j)) + (layout.half_width + max(r, inset)) * (u + v)
    phi = np.linspace(-0.5 * math.pi, -math.pi, CORNER_SEGMENTS + 1)
    radius = max(r - inset, 0.0)
    out: FloatArray = centre + radius * (np.cos(phi)[:, None] * u + np.sin(phi)[:, None] * v)
    return out


def junction_outline(layout: TownLayout, j: Index) -> FloatArray:
    """(K, 2) [m] the edge of junction j's asphalt, counter-clockwise: star-shaped from the
    centre. Per quadrant: the rounded kerb where both its streets exist, else the corner of
    the mouth of the one that exists and the kerb that runs on, or the box's corner."""
    arms = set(layout.arms(j))
    hw, mouth = layout.half_width, layout.mouth
    centre = np.array(layout.centre(j))
    points: list[FloatArray] = []
    for k in range(4):
        u, v = _axes(k)
        along_u, along_v = _QUADRANTS[k] in arms, _QUADRANTS[(k + 1) % 4] in arms
        if along_u and along_v:
            points.append(corner_arc(layout, j, k))
        elif along_u:  # the kerb of the street along u runs on past the junction
            points.append((centre + mouth * u + hw * v)[None, :])
        elif along_v:
            points.append((centre + hw * u + mouth * v)[None, :])
        else:  # the outer corner of a bend: square
            points.append((centre + hw * u + hw * v)[None, :])
    return np.concatenate(points)


def block_outline(layout: TownLayout, block: Index, inset: float = 0.0) -> FloatArray:
    """(4 (CORNER_SEGMENTS + 1), 2) [m] the kerb around block (bx, by) (between junctions
    (bx, by) and (bx + 1, by + 1)), counter-clockwise, moved `inset` into the block."""
    bx, by = block
    corners = (((bx, by), 0), ((bx + 1, by), 1), ((bx + 1, by + 1), 2), ((bx, by + 1), 3))
    return np.concatenate([corner_arc(layout, j, k, inset)[::-1] for j, k in corners])


def street_road(layout: TownLayout, j: Index, heading: str) -> RoadMap:
    """The street leaving junction j `heading` ("east" or "north") as a one-segment road from
    mouth to mouth: n lanes each way, no shoulder, its reference line lane 0 of `heading`."""
    t = layout.spec
    n, w = t.lanes, t.lane_width
    segment = SegmentSpec(t.block - 2.0 * layout.mouth, 0.0, n, n, w, 0.0, None, Zone.CITY)
    origin = (*layout.point(j, heading, layout.mouth, layout.kerb_lane), HEADINGS[heading])
    return build_road_map(RoadSpec((segment,), t.speed_limit, origin=origin))


# -- meshes ----------------------------------------------------------------------------------

Part = tuple[FloatArray, IntArray, FloatArray]  # vertices (N, 3), triangles (M, 3), uvs (N, 2)


def _merge(name: str, parts: list[Part], texture: NDArray[np.uint8],
           normals: list[FloatArray] | None = None) -> list[TexturedMesh]:
    """Parts sharing one texture as meshes of at most MAX_MESH_VERTICES, named
    `<name>_<k>`; normals +z unless given per part."""
    meshes: list[TexturedMesh] = []
    batch: list[int] = []

    def flush() -> None:
        if not batch:
            return
        base = np.cumsum([0] + [len(parts[i][0]) for i in batch])
        vertices = np.concatenate([parts[i][0] for i in batch])
        if normals is None:
            up = np.zeros_like(vertices)
            up[:, 2] = 1.0
        else:
            up = np.concatenate([normals[i] for i in batch])
        meshes.append(TexturedMesh(
            name=f"{name}_{len(meshes)}", vertices=vertices,
            indices=np.concatenate([parts[i][1] + b for i, b in zip(batch, base, strict=False)]),
            uvs=np.concatenate([parts[i][2] for i in batch]), normals=up, texture=texture))
        batch.clear()

    count = 0
    for i, (vertices, _, _) in enumerate(parts):
        if count + len(vertices) > MAX_MESH_VERTICES:
            flush()
            count = 0
        batch.append(i)
        count += len(vertices)
    flush()
    return meshes


def build_streets(layout: TownLayout) -> list[TexturedMesh]:
    """Every street's strip with its markings (`build_road_surface` of `street_road`),
    merged. The streets of one heading differ only by where they start: the first one's
    strip is built, the others are it moved (the same vertices as building each, and the
    texture is made once)."""
    parts: list[Part] = []
    texture: NDArray[np.uint8] | None = None
    first: dict[str, tuple[FloatArray, list[TexturedMesh]]] = {}
    for j, heading in layout.streets():
        start = np.array([*layout.point(j, heading, layout.mouth, layout.kerb_lane), 0.0])
        if heading not in first:
            first[heading] = (start, build_road_surface(street_road(layout, j, heading)))
        origin, meshes = first[heading]
        for mesh in meshes:
            texture = mesh.texture if texture is None else texture
            parts.append((mesh.vertices + (start - origin), mesh.indices, mesh.uvs))
    return [] if texture is None else _merge("town_streets", parts, texture)


def asphalt_texture(size: float) -> NDArray[np.uint8]:
    """(n, n, 3) uint8 plain asphalt for a square of `size` [m], JUNCTION_TEXEL per pixel,
    with the road texture's noise."""
    n = max(1, round(size / JUNCTION_TEXEL))
    rng = np.random.default_rng(TEXTURE_SEED)
    image = np.asarray(ASPHALT_RGB) + rng.normal(0.0, ASPHALT_NOISE, size=(n, n, 1))
    return np.clip(np.rint(image), 0, 255).astype(np.uint8)


def _fan(centre: FloatArray, ring: FloatArray, z: float) -> tuple[FloatArray, IntArray]:
    """(vertices (K + 1, 3), triangles (K, 3)) of a closed fan: the centre, then the ring
    (K, 2) counter-clockwise about it."""
    k = len(ring)
    vertices = np.column_stack([np.vstack([centre, ring]), np.full(k + 1, z)])
    i = np.arange(k)
    triangles = np.column_stack([np.zeros(k, int), 1 + i, 1 + (i + 1) % k]).astype(np.int32)
    return vertices, triangles


def build_junctions(layout: TownLayout) -> list[TexturedMesh]:
    """Every junction's asphalt (`junction_outline`) as one fan each, merged; the texture
    spans the square of `mouth` about each centre."""
    parts: list[Part] = []
    size = 2.0 * layout.mouth
    for j in layout.junctions():
        centre = np.array(layout.centre(j))
        vertices, triangles = _fan(centre, junction_outline(layout, j), SURFACE_Z)
        uvs = (vertices[:, :2] - centre + layout.mouth) / size
        parts.append((vertices, triangles, uvs))
    return _merge("town_junctions", parts, asphalt_texture(size))


def stop_line_corners(layout: TownLayout, j: Index, heading: str) -> FloatArray:
    """(4, 2) [m] the stop line of the approach into junction j heading `heading`,
    counter-clockwise: near edge at the stop line, from the kerb to the centre line, then
    the far edge STOP_LINE_WIDTH on."""
    near = -(layout.mouth + STOP_SETBACK)
    far = near + STOP_LINE_WIDTH
    hw = layout.half_width
    return np.array([layout.point(j, heading, a, r)
                     for a, r in ((near, hw), (far, hw), (far, 0.0), (near, 0.0))])


def build_stop_lines(layout: TownLayout) -> list[TexturedMesh]:
    """The stop line of every approach (`stop_line_corners`), in one white mesh."""
    parts: list[Part] = []
    uv = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    quad = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int32)
    for a in layout.approaches():
        corners = stop_line_corners(layout, a.junction, a.heading)
        parts.append((np.column_stack([corners, np.full(4, MARK_Z)]), quad, uv))
    return _merge("town_stop_lines", parts, paint_texture()) if parts else []


# -- pavements -------------------------------------------------------------------------------


def pavement_texture() -> NDArray[np.uint8]:
    """(PAVEMENT_TEXELS, 2 PAVEMENT_TEXELS, 3) uint8: concrete on the left, ground right."""
    image = np.empty((PAVEMENT_TEXELS, 2 * PAVEMENT_TEXELS, 3), np.uint8)
    image[:, :PAVEMENT_TEXELS] = CONCRETE_RGB
    image[:, PAVEMENT_TEXELS:] = GROUND_RGB
    return image


def _sides(outline: FloatArray, height: float) -> tuple[FloatArray, IntArray, FloatArray]:
    """(vertices (4K, 3), triangles (2K, 3), normals (4K, 3)) of the vertical faces of a
    counter-clockwise outline (K, 2) from z = 0 to `height`, facing out."""
    a, b = outline, np.roll(outline, -1, axis=0)
    k = len(outline)
    z0, zh = np.zeros(k), np.full(k, height)
    vertices = np.stack([np.column_stack([a, z0]), np.column_stack([b, z0]),
                         np.column_stack([b, zh]), np.column_stack([a, zh])], axis=1)
    d = b - a
    out = np.column_stack([d[:, 1], -d[:, 0], np.zeros(k)])
    out /= np.maximum(np.linalg.norm(out, axis=1, keepdims=True), 1e-12)
    i = 4 * np.arange(k)[:, None]
    triangles = np.concatenate([i + np.array([0, 1, 2]), i + np.array([0, 2, 3])])
    return vertices.reshape(-1, 3), triangles.astype(np.int32), np.repeat(out, 4, axis=0)


def _ring(outer: FloatArray, inner: FloatArray, z: float) -> tuple[FloatArray, IntArray]:
    """(vertices (2K, 3), triangles (2K, 3)) of the band between two counter-clockwise
    outlines (K, 2) whose points correspond."""
    k = len(outer)
    vertices = np.column_stack([np.vstack([outer, inner]), np.full(2 * k, z)])
    i = np.arange(k)
    j = (i + 1) % k
    triangles = np.concatenate([np.column_stack([i, j, k + j]),
                                np.column_stack([i, k + j, k + i])]).astype(np.int32)
    return vertices, triangles


def pavement(name: str, outline: FloatArray, inner: FloatArray | None = None,
             height: float = KERB_HEIGHT) -> Pavement:
    """A slab of a convex counter-clockwise `outline`: concrete kerb faces and top, or, with
    `inner` (the outline's points moved into it), a concrete band down to `inner` and the
    ground colour within it."""
    pieces: list[tuple[FloatArray, IntArray, FloatArray, tuple[float, float]]] = []
    up = np.array([0.0, 0.0, 1.0])
    if inner is None:
        v, t = _fan(outline.mean(axis=0), outline, height)
        pieces.append((v, t, np.tile(up, (len(v), 1)), _CONCRETE_UV))
    else:
        v, t = _ring(outline, inner, height)
        pieces.append((v, t, np.tile(up, (len(v), 1)), _CONCRETE_UV))
        v, t = _fan(inner.mean(axis=0), inner, height)
        pieces.append((v, t, np.tile(up, (len(v), 1)), _GROUND_UV))
    pieces.append((*_sides(outline, height), _CONCRETE_UV))
    base = np.cumsum([0] + [len(p[0]) for p in pieces])
    mesh = TexturedMesh(
        name=name, vertices=np.concatenate([p[0] for p in pieces]),
        indices=np.concatenate([p[1] + b for p, b in zip(pieces, base, strict=False)]),
        uvs=np.concatenate([np.tile(p[3], (len(p[0]), 1)) for p in pieces]),
        normals=np.concatenate([p[2] for p in pieces]), texture=pavement_texture())
    return Pavement(name, outline, height, mesh)


def _rectangle(x0: float, y0: float, x1: float, y1: float) -> FloatArray:
    """(4, 2) [m] the corners of an axis-aligned rectangle, counter-clockwise."""
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])


def build_pavements(layout: TownLayout) -> list[Pavement]:
    """A slab per block (row by row from the south-west), then the outer sidewalks: south,
    east, north, west."""
    t = layout.spec
    slabs = [pavement(f"town_block_{bx}_{by}", block_outline(layout, (bx, by)),
                      block_outline(layout, (bx, by), SIDEWALK_WIDTH))
             for by in range(t.blocks_y) for bx in range(t.blocks_x)]
    hw, w = layout.half_width, SIDEWALK_WIDTH
    x0, y0 = -hw, -hw
    x1, y1 = t.blocks_x * t.block + hw, t.blocks_y * t.block + hw
    strips = {"south": _rectangle(x0 - w, y0 - w, x1 + w, y0),
              "east": _rectangle(x1, y0, x1 + w, y1),
              "north": _rectangle(x0 - w, y1, x1 + w, y1 + w),
              "west": _rectangle(x0 - w, y0, x0, y1)}
    return slabs + [pavement(f"town_edge_{side}", box) for side, box in strips.items()]


# -- buildings -------------------------------------------------------------------------------


def building_zone(layout: TownLayout, block: Index) -> tuple[float, float, float, float]:
    """([m] x0, y0, x1, y1) where block (bx, by)'s buildings may stand: BUILDING_SETBACK
    behind its sidewalk (beyond the sidewalk's rounded inner corners too)."""
    t = layout.spec
    margin = layout.half_width + max(SIDEWALK_WIDTH + BUILDING_SETBACK, layout.corner_radius)
    x, y = block[0] * t.block, block[1] * t.block
    return x + margin, y + margin, x + t.block - margin, y + t.block - margin


def _aabb(box: BuildingBox) -> Rect:
    """[m] x0, y0, x1, y1 of the box's footprint."""
    corners = box.footprint()
    x0, y0 = corners.min(axis=0)
    x1, y1 = corners.max(axis=0)
    return float(x0), float(y0), float(x1), float(y1)


def _side_buildings(zone: tuple[float, float, float, float], side: int,
                    rng: np.random.Generator, boxes: list[BuildingBox],
                    placed: BoxIndex) -> None:
    """Walk side `side` (0 south, 1 east, 2 north, 3 west) of the zone counter-clockwise,
    adding boxes whose front is on it (module doc)."""
    x0, y0, x1, y1 = zone
    length = (x1 - x0) if side % 2 == 0 else (y1 - y0)
    span = (y1 - y0) if side % 2 == 0 else (x1 - x0)
    yaw = 0.5 * math.pi * side if side < 3 else -0.5 * math.pi
    u, v = _axes(side)
    start = {0: (x0, y0), 1: (x1, y0), 2: (x1, y1), 3: (x0, y1)}[side]
    gap_factor = (1.0 - BUILDING_DENSITY) / BUILDING_DENSITY
    t = float(rng.uniform(0.0, START_JITTER))
    while t < length:
        frontage = float(rng.uniform(*BUILDING_FRONTAGE))
        depth = min(float(rng.uniform(*DEPTH_RANGE)), 0.5 * span - MIN_BUILDING_GAP)
        height = float(rng.uniform(*HEIGHT_RANGE))
        rgb = _facade(rng)
        gap = max(MIN_BUILDING_GAP, frontage * gap_factor * float(rng.uniform(*GAP_JITTER)))
        if t + frontage <= length and depth > 0.0:
            # u runs along the side, v (u turned left) into the zone
            xy = np.array(start) + (t + 0.5 * frontage) * u + 0.5 * depth * v
            box = BuildingBox((float(xy[0]), float(xy[1]), 0.5 * height),
                              (0.5 * frontage, 0.5 * depth, 0.5 * height), yaw, rgb)
            rect = _aabb(box)
            if placed.clear(rect):  # MIN_BUILDING_GAP from every other box (axis-aligned)
                boxes.append(box)
                placed.add(rect)
        t += frontage + gap


def layout_town_buildings(layout: TownLayout, rng: np.random.Generator) -> list[BuildingBox]:
    """Buildings along the four sides of every block's zone (`building_zone`), block by block
    row by row from the south-west, each block's sides south, east, north, west."""
    boxes: list[BuildingBox] = []
    placed = BoxIndex(MIN_BUILDING_GAP, INDEX_CELL)
    t = layout.spec
    for by in range(t.blocks_y):
        for bx in range(t.blocks_x):
            zone = building_zone(layout, (bx, by))
            if zone[2] - zone[0] < BUILDING_FRONTAGE[0] or zone[3] - zone[1] < BUILDING_FRONTAGE[0]:
                continue
            for side in range(4):
                _side_buildings(zone, side, rng, boxes, placed)
    return boxes


# -- the whole scene -------------------------------------------------------------------------


def town_stop_signs(layout: TownLayout) -> list[StopSignPlacement]:
    """A stop sign at every approach that has one, in `approaches()` order."""
    return [StopSignPlacement(s=0.0, pole_xy=a.stop_sign[0], yaw=a.stop_sign[1])
            for a in layout.approaches() if a.stop_sign is not None]


def build_town_scene(layout: TownLayout, rng: np.random.Generator) -> TownScene:
    """Everything static of the town (module doc); the rng draws the buildings only."""
    return TownScene(
        streets=tuple(build_streets(layout)),
        junctions=tuple(build_junctions(layout)),
        stop_lines=tuple(build_stop_lines(layout)),
        pavements=tuple(build_pavements(layout)),
        buildings=tuple(layout_town_buildings(layout, rng)),
        stop_signs=tuple(town_stop_signs(layout)),
    )
