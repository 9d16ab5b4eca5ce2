"""A traffic light's body: a pole, a dark housing with visors and three lamps, one of them lit.

`add_traffic_light(client, head)` builds it around a `LightHead` (the housing's centre, which
is the yellow lamp, and the yaw its lamps face) and returns a `TrafficLightBody`, whose
`set_colour` lights one lamp. Which lamp is lit when is `world.map.signals.light_colour`'s
business; the body only shows it.

The pole (from the ground up to the housing, below its centre) and the housing are one
static body with collision (a cylinder and a box), an obstacle like a sign pole. The lamps
are visual-only discs, red on top, yellow at the head's centre, green at the bottom,
``LAMP_SPACING`` apart, each under a thin visor. A lit lamp is a bright saturated colour,
an unlit one a dark version of it; `set_colour` recolours with `changeVisualShape` only when
the colour changes. PyBullet has no emissive material: a lit lamp is as bright as the
renderer's default light makes a bright surface (`perception.lights` documents the rendered
HSV: saturation, not brightness, is what sets a lamp apart from a red car).

Why meshes: the EGL renderer's depth buffer is coarse, so a face centimetres in front of
another is lost behind it from a few tens of metres away, and a lamp on the front of a box
housing would vanish at the distances the camera must see it from. Both renderers cull back
faces of meshes, so the housing is a single-sided OBJ mesh, a closed box with three round
holes in its front face, and each lamp a single-sided disc filling its hole: seen from the
front nothing lies behind a lamp but the housing's back face, which faces away and is
culled; seen from behind the back face hides the lamps, whose discs are culled. The meshes
go through Wavefront OBJ files (the EGL plugin drops meshes given as vertex arrays), written
into ``folder`` once (every light there shares them; a temporary directory the body keeps
when none is given).
"""

from __future__ import annotations

import math
import tempfile
from collections.abc import Mapping
from itertools import pairwise
from pathlib import Path

import numpy as np
import pybullet
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from world.hdmap import LightColour, LightHead
from world.scene import collision
from world.scene.collision import CollisionShapes, Cylinder, Part

HOUSING_DEPTH = 0.25  # [m] along the facing
HOUSING_WIDTH = 0.35  # [m] across the facing
HOUSING_HEIGHT = 1.0  # [m] top to bottom
LAMP_DIAMETER = 0.22  # [m] a lamp disc's
LAMP_SPACING = 0.30  # [m] centre to centre, vertically
LAMP_SEGMENTS = 24  # [-] sides of a lamp's polygon
VISOR_DEPTH = 0.15  # [m] how far a visor reaches out over its lamp
VISOR_THICKNESS = 0.02  # [m] a visor's plate
VISOR_GAP = 0.01  # [m] between a lamp's top and its visor
POLE_RADIUS = 0.06  # [m] the pole's cylinder

HOUSING_RGBA = (0.07, 0.07, 0.07, 1.0)  # [-] matt black
POLE_RGBA = (0.6, 0.6, 0.62, 1.0)  # [-] galvanised steel (as sign poles)
LIT_RGBA = {  # [-] a lit lamp's colour
    LightColour.RED: (1.0, 0.04, 0.0, 1.0),
    LightColour.YELLOW: (1.0, 0.72, 0.0, 1.0),
    LightColour.GREEN: (0.0, 1.0, 0.45, 1.0),
}
DIM_FACTOR = 0.22  # [-] an unlit lamp's colour is the lit one's times this (dark glass)
LAMP_HEIGHT = {  # [m] lamp centre above the head's centre
    LightColour.RED: LAMP_SPACING,
    LightColour.YELLOW: 0.0,
    LightColour.GREEN: -LAMP_SPACING,
}

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int32]
Box = tuple[tuple[float, float, float], tuple[float, float, float]]  # [m] centre, half extents


def dim_rgba(colour: LightColour) -> tuple[float, float, float, float]:
    """[-] the unlit lamp's colour: the lit one darkened by `DIM_FACTOR`."""
    r, g, b, a = LIT_RGBA[colour]
    return (DIM_FACTOR * r, DIM_FACTOR * g, DIM_FACTOR * b, a)


class TrafficLightBody:
    """The bodies of one traffic light in one client, and which lamp is lit."""

    def __init__(self, client: BulletClient, body: int, lamps: Mapping[LightColour, int],
                 keep: tempfile.TemporaryDirectory[str] | None = None) -> None:
        """`keep`: the temporary directory of the mesh files, kept alive with the body."""
        self._c = client
        self.body = body  # the pole and housing: static, with collision (an obstacle)
        self.lamps = dict(lamps)  # visual-only lamp bodies
        self.colour: LightColour | None = None  # the lit lamp; None: all dark
        self._keep = keep  # the temporary directory of the mesh files, if ours

    def set_colour(self, colour: LightColour) -> None:
        """Light `colour`'s lamp and darken the one lit before (nothing when unchanged)."""
        if colour is self.colour:
            return
        if self.colour is not None:
            self._c.changeVisualShape(self.lamps[self.colour], -1,
                                      rgbaColor=list(dim_rgba(self.colour)))
        self._c.changeVisualShape(self.lamps[colour], -1, rgbaColor=list(LIT_RGBA[colour]))
        self.colour = colour


def add_traffic_light(client: BulletClient, head: LightHead, folder: Path | None = None,
                      shapes: CollisionShapes | None = None) -> TrafficLightBody:
    """Build a traffic light at `head` in `client`, all lamps dark. The mesh files go into
    `folder` (which must outlive the client's use of them; the world's own temporary
    directory), or a temporary directory that the returned body keeps. `shapes` keeps the
    collision shape's description (a book of its own when None)."""
    if head.z <= 0.5 * HOUSING_HEIGHT:
        raise ValueError(f"a light head {head.z} m high leaves no room for its pole")
    keep = None
    if folder is None:
        keep = tempfile.TemporaryDirectory(prefix="avsim-light-")
        folder = Path(keep.name)
    housing = folder / "light_housing.obj"
    disc = folder / "light_lamp.obj"
    if not housing.exists():
        write_obj(housing, *housing_mesh())
    if not disc.exists():
        write_obj(disc, *disc_mesh(0.5 * LAMP_DIAMETER, LAMP_SEGMENTS))
    body = _add_pole_and_housing(client, head, housing,
                                 CollisionShapes() if shapes is None else shapes)
    lamps = {colour: _add_lamp(client, head, colour, disc) for colour in LightColour}
    return TrafficLightBody(client, body, lamps, keep)


def _add_pole_and_housing(client: BulletClient, head: LightHead, housing: Path,
                          shapes: CollisionShapes) -> int:
    """One static body at the head, yawed to its facing (body x = the lamps' normal): for
    collision a box and the pole below it; for the eye the housing mesh, the visors and
    the pole."""
    pole_length = head.z - 0.5 * HOUSING_HEIGHT
    pole_centre = (0.0, 0.0, -0.5 * HOUSING_HEIGHT - 0.5 * pole_length)
    housing_half = (0.5 * HOUSING_DEPTH, 0.5 * HOUSING_WIDTH, 0.5 * HOUSING_HEIGHT)
    shape = shapes.create(client, Part(collision.Box(housing_half)),
                          Part(Cylinder(POLE_RADIUS, pole_length), pole_centre))
    visors = visor_boxes()
    n = len(visors)
    visual = client.createVisualShapeArray(
        [pybullet.GEOM_MESH, pybullet.GEOM_CYLINDER] + [pybullet.GEOM_BOX] * n,
        fileNames=[str(housing), ""] + [""] * n,
        halfExtents=[[0.0, 0.0, 0.0]] * 2 + [list(half) for _, half in visors],
        radii=[0.0, POLE_RADIUS] + [0.0] * n, lengths=[0.0, pole_length] + [0.0] * n,
        visualFramePositions=[[0.0, 0.0, 0.0], list(pole_centre)]
        + [list(centre) for centre, _ in visors],
        rgbaColors=[list(HOUSING_RGBA), list(POLE_RGBA)] + [list(HOUSING_RGBA)] * n)
    quat = client.getQuaternionFromEuler([0.0, 0.0, head.facing])
    return shapes.placed(int(client.createMultiBody(0.0, shape, visual,
                                                    [head.x, head.y, head.z], quat,
                                                    useMaximalCoordinates=True)), shape)


def _add_lamp(client: BulletClient, head: LightHead, colour: LightColour, disc: Path) -> int:
    """A visual-only lamp disc filling its hole of the housing's front face, facing out
    (in the hole's plane: in front of it, it would show a crack of the hollow housing)."""
    ahead = 0.5 * HOUSING_DEPTH  # [m] in front of the head's centre
    cos, sin = math.cos(head.facing), math.sin(head.facing)
    centre = [head.x + ahead * cos, head.y + ahead * sin, head.z + LAMP_HEIGHT[colour]]
    visual = client.createVisualShape(pybullet.GEOM_MESH, fileName=str(disc),
                                      rgbaColor=list(dim_rgba(colour)))
    quat = client.getQuaternionFromEuler([0.0, 0.0, head.facing])
    return int(client.createMultiBody(0.0, -1, visual, centre, quat,
                                      useMaximalCoordinates=True))


def visor_boxes() -> list[Box]:
    """[m] A thin visor over each lamp, reaching `VISOR_DEPTH` out of the front face, in the
    head's frame (x along the facing, y left, z up, origin at the housing's centre)."""
    x = 0.5 * HOUSING_DEPTH + 0.5 * VISOR_DEPTH
    half = (0.5 * VISOR_DEPTH, 0.5 * LAMP_DIAMETER + 0.02, 0.5 * VISOR_THICKNESS)
    return [((x, 0.0, z + 0.5 * LAMP_DIAMETER + VISOR_GAP + 0.5 * VISOR_THICKNESS), half)
            for z in LAMP_HEIGHT.values()]


# ---- meshes (pure geometry) -------------------------------------------------------------


def disc_mesh(radius: float, sides: int) -> tuple[FloatArray, IntArray]:
    """A regular polygon in the y-z plane facing +x: vertices [m] (sides + 1, 3), the centre
    first, and triangles (sides, 3), counter-clockwise seen from +x."""
    angles = 2.0 * math.pi * np.arange(sides) / sides
    ring = np.column_stack([np.zeros(sides), radius * np.cos(angles), radius * np.sin(angles)])
    vertices = np.vstack([np.zeros((1, 3)), ring])
    k = np.arange(sides)
    faces = np.column_stack([np.zeros(sides), 1 + k, 1 + (k + 1) % sides]).astype(np.int32)
    return vertices, faces


def housing_mesh() -> tuple[FloatArray, IntArray]:
    """The housing's outer surface in the head's frame: a closed box, faces outward, with a
    round hole of `LAMP_DIAMETER` in its front face (x = +depth / 2) at each lamp.
    Vertices [m] (N, 3) and triangles (M, 3)."""
    dx, dy, dz = 0.5 * HOUSING_DEPTH, 0.5 * HOUSING_WIDTH, 0.5 * HOUSING_HEIGHT
    quads = [
        [(-dx, dy, -dz), (-dx, -dy, -dz), (-dx, -dy, dz), (-dx, dy, dz)],  # back, -x
        [(dx, dy, -dz), (-dx, dy, -dz), (-dx, dy, dz), (dx, dy, dz)],  # left, +y
        [(-dx, -dy, -dz), (dx, -dy, -dz), (dx, -dy, dz), (-dx, -dy, dz)],  # right, -y
        [(dx, -dy, dz), (dx, dy, dz), (-dx, dy, dz), (-dx, -dy, dz)],  # top, +z
        [(dx, dy, -dz), (dx, -dy, -dz), (-dx, -dy, -dz), (-dx, dy, -dz)],  # bottom, -z
    ]
    vertices = [np.array(q, np.float64) for q in quads]
    faces = [np.array([[0, 1, 2], [0, 2, 3]], np.int32) for _ in quads]
    lamps = sorted(LAMP_HEIGHT.values())  # [m] lamp centres, bottom up
    cuts = [-dz] + [0.5 * (a + b) for a, b in pairwise(lamps)] + [dz]  # one cell per lamp
    for (low, high), z in zip(pairwise(cuts), lamps, strict=True):
        v, f = holed_rectangle((dy, high - z), (-dy, low - z), 0.5 * LAMP_DIAMETER,
                               LAMP_SEGMENTS)
        vertices.append(np.column_stack([np.full(len(v), dx), v[:, 0], v[:, 1] + z]))
        faces.append(f)
    offsets = np.cumsum([0] + [len(v) for v in vertices[:-1]])
    return (np.vstack(vertices),
            np.vstack([f + o for f, o in zip(faces, offsets, strict=True)]).astype(np.int32))


def holed_rectangle(corner_a: tuple[float, float], corner_b: tuple[float, float],
                    radius: float, sides: int) -> tuple[FloatArray, IntArray]:
    """A rectangle in a (p, q) plane with a hole at the origin, which it must contain: the
    regular polygon of ``sides`` and circumradius ``radius`` that `disc_mesh` makes. Points
    (N, 2) [m] and triangles (M, 3), counter-clockwise in (p, q).

    Each ring direction (the polygon's vertices plus the rectangle's four corners) gives a
    point on the hole and one on the rectangle's edge; quads join neighbours."""
    p_max, p_min = max(corner_a[0], corner_b[0]), min(corner_a[0], corner_b[0])
    q_max, q_min = max(corner_a[1], corner_b[1]), min(corner_a[1], corner_b[1])
    corners = [math.atan2(q, p) % (2 * math.pi)
               for p, q in ((p_max, q_max), (p_min, q_max), (p_min, q_min), (p_max, q_min))]
    angles = np.unique(np.concatenate([2.0 * math.pi * np.arange(sides) / sides, corners]))
    c, s = np.cos(angles), np.sin(angles)
    with np.errstate(divide="ignore"):  # an axis direction never reaches the other pair
        reach = np.minimum(np.where(c > 0, p_max / c, np.where(c < 0, p_min / c, np.inf)),
                           np.where(s > 0, q_max / s, np.where(s < 0, q_min / s, np.inf)))
    step = 2.0 * math.pi / sides  # the hole is the lamp disc's polygon (`disc_mesh`) exactly
    polygon = radius * math.cos(0.5 * step) / np.cos(np.mod(angles, step) - 0.5 * step)
    inner = polygon[:, None] * np.column_stack([c, s])
    outer = reach[:, None] * np.column_stack([c, s])
    n = len(angles)
    k = np.arange(n)
    nxt = (k + 1) % n
    faces = np.vstack([np.column_stack([k, n + k, n + nxt]), np.column_stack([k, n + nxt, nxt])])
    return np.vstack([inner, outer]), faces.astype(np.int32)


def write_obj(path: Path, vertices: FloatArray, faces: IntArray) -> None:
    """A flat-shaded triangle mesh as a Wavefront OBJ (one normal per face, from its
    winding)."""
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    normals = np.cross(b - a, c - a)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in vertices]
    lines += [f"vn {x:.6f} {y:.6f} {z:.6f}" for x, y, z in normals]
    lines += [f"f {i + 1}//{n + 1} {j + 1}//{n + 1} {k + 1}//{n + 1}"
              for n, (i, j, k) in enumerate(faces)]
    path.write_text("\n".join(lines) + "\n")
