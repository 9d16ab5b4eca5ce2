"""Speed bumps: real geometry the car rides over, as layout data (no PyBullet).

A bump is a prism square to the route at its station: its profile along the route is a
circular segment (chord = the feature's `length`, rise = its `height`), so a wheel rolls up a
slope instead of hitting a step, and it runs across the ego-direction lanes and the shoulder
(from the right paved edge to the centre line). The world builder makes it two bodies: a
static collision body, the convex hull of `hull_vertices` (the profile's points at both
ends: a convex prism), and a visual-only textured mesh (`bump_mesh`, yellow and white
stripes across the road) lifted `VISUAL_LIFT` above the collision surface so that its foot
shows over the road surface.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from world.hdmap import RoadMap, SpeedBump
from world.scene.road_mesh import TexturedMesh

FloatArray = NDArray[np.float64]

BUMP_SEGMENTS = 16  # [-] straight pieces of the profile along the route
VISUAL_LIFT = 0.008  # [m] the visual surface above the collision surface (as the road marks)
STRIPE_WIDTH = 0.5  # [m] a stripe's width across the road, alternately yellow and white
STRIPE_TEXELS = 4  # [px] per stripe across the texture
YELLOW_RGB = (235, 190, 20)  # [0..255]
WHITE_RGB = (235, 235, 230)  # [0..255]


@dataclass(frozen=True, slots=True)
class BumpPlacement:
    """A speed bump in the map frame: a prism across the road, centred on (s, band middle)."""

    s: float  # [m] station of the bump's centre line (the crest)
    centre: tuple[float, float]  # [m] map frame, on the ground below the crest's middle
    yaw: float  # [rad] route heading at s: the bump's local x runs along the route
    band: tuple[float, float]  # [m] (right, left) offsets from the reference line it spans
    height: float  # [m] rise at the crest
    length: float  # [m] along the route (the profile's chord)
    pass_speed: float  # [m/s] the speed to take it at

    @property
    def half_width(self) -> float:
        """[m] half the bump's extent across the road."""
        return 0.5 * (self.band[1] - self.band[0])


def bump_profile(height: float, length: float,
                 n: int = BUMP_SEGMENTS) -> tuple[FloatArray, FloatArray]:
    """(x (n + 1,), z (n + 1,)) [m] the circular-segment profile: x from -length / 2 to
    length / 2 along the route, z the rise above the ground (0 at both ends, `height` at
    x = 0). The circle's radius is (length^2 / 4 + height^2) / (2 height)."""
    radius = (0.25 * length**2 + height**2) / (2.0 * height)
    x = np.linspace(-0.5 * length, 0.5 * length, n + 1)
    z = np.sqrt(np.maximum(radius**2 - x**2, 0.0)) - (radius - height)
    z[[0, -1]] = 0.0
    return x, np.maximum(z, 0.0)


def layout_speed_bumps(road_map: RoadMap) -> list[BumpPlacement]:
    """A bump for each `SpeedBump` feature, in station order, across the ego-direction lanes
    and the shoulder: from the right paved edge to the centre line."""
    bumps = []
    for f in road_map.features:
        if not isinstance(f, SpeedBump):
            continue
        bounds = road_map.lane_boundaries(f.s)
        band = (float(bounds[0]), float(bounds[road_map.cross_section_at(f.s).lanes + 1]))
        xy = road_map.position(f.s, 0.5 * (band[0] + band[1]))
        bumps.append(BumpPlacement(
            s=f.s, centre=(float(xy[0]), float(xy[1])), yaw=float(road_map.heading_at(f.s)),
            band=band, height=f.height, length=f.length, pass_speed=f.pass_speed,
        ))
    return bumps


def hull_vertices(bump: BumpPlacement) -> FloatArray:
    """(2 (n + 1), 3) [m] the collision prism's corners in the bump's own frame (x along the
    route, y left, z up, origin on the ground at its centre): the profile at y = -half width
    and at y = +half width. Their convex hull is the prism (the profile is convex)."""
    x, z = bump_profile(bump.height, bump.length)
    hw = bump.half_width
    right = np.column_stack([x, np.full_like(x, -hw), z])
    left = np.column_stack([x, np.full_like(x, hw), z])
    return np.vstack([right, left])


def bump_height_at(bump: BumpPlacement, along: FloatArray) -> FloatArray:
    """[m] the collision surface's height at `along` [m] from the crest along the route
    (0 beyond the ends): the exact circle, which the hull's chords stay below by at most
    (length / n)^2 / (8 radius)."""
    radius = (0.25 * bump.length**2 + bump.height**2) / (2.0 * bump.height)
    a = np.asarray(along, dtype=np.float64)
    z = np.sqrt(np.maximum(radius**2 - a**2, 0.0)) - (radius - bump.height)
    return np.where(np.abs(a) <= 0.5 * bump.length, np.maximum(z, 0.0), 0.0)


def bump_texture(bump: BumpPlacement) -> NDArray[np.uint8]:
    """(STRIPE_TEXELS, W, 3) uint8: alternate yellow and white stripes across the bump,
    STRIPE_WIDTH each (the first, at the right end, yellow); column 0 is the right end."""
    stripes = max(1, round(2.0 * bump.half_width / STRIPE_WIDTH))
    colours = np.array([YELLOW_RGB if i % 2 == 0 else WHITE_RGB for i in range(stripes)],
                       dtype=np.uint8)
    row = np.repeat(colours, STRIPE_TEXELS, axis=0)
    return np.ascontiguousarray(np.broadcast_to(row, (STRIPE_TEXELS, *row.shape)))


def bump_mesh(bump: BumpPlacement, index: int = 0) -> TexturedMesh:
    """The bump's visible surface in the map frame, named `speed_bump_<index>`: the profile
    (lifted VISUAL_LIFT) swept across the band, with u running across (0 at the right end)
    and v along, plus the two end caps."""
    x, z = bump_profile(bump.height, bump.length)
    z = z + VISUAL_LIFT
    n = len(x)
    hw = bump.half_width
    c, s = math.cos(bump.yaw), math.sin(bump.yaw)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    origin = np.array([*bump.centre, 0.0])
    # top: vertex 2 i at the right end, 2 i + 1 at the left end of profile point i
    local = np.stack([np.column_stack([x, np.full(n, -hw), z]),
                      np.column_stack([x, np.full(n, hw), z])], axis=1).reshape(-1, 3)
    slope = np.gradient(z, x)
    top_normal = np.column_stack([-slope, np.zeros(n), np.ones(n)])
    top_normal /= np.linalg.norm(top_normal, axis=1, keepdims=True)
    normals = np.repeat(top_normal, 2, axis=0)
    v = np.linspace(0.0, 1.0, n)
    uvs = np.stack([np.zeros(n), v, np.ones(n), v], axis=1).reshape(-1, 2)
    i = 2 * np.arange(n - 1)
    r0, l0, r1, l1 = i, i + 1, i + 2, i + 3
    tris = [np.stack([np.stack([r0, r1, l1], 1), np.stack([r0, l1, l0], 1)], 1).reshape(-1, 3)]
    # end caps: fans in the planes y = -hw (facing right) and y = +hw (facing left)
    parts_v, parts_n, parts_uv = [local], [normals], [uvs]
    base = len(local)
    for side, u in ((-1.0, 0.0), (1.0, 1.0)):
        cap = np.column_stack([x, np.full(n, side * hw), z])
        foot = np.array([[0.0, side * hw, 0.0]])
        parts_v.append(np.vstack([foot, cap]))
        parts_n.append(np.tile([0.0, side, 0.0], (n + 1, 1)))
        parts_uv.append(np.tile([u, 0.5], (n + 1, 1)))
        k = np.arange(n - 1)
        fan = np.column_stack([np.zeros(n - 1), 1 + k, 2 + k]).astype(np.int64) + base
        tris.append(fan[:, [0, 2, 1]] if side < 0 else fan)  # counter-clockwise seen from outside
        base += n + 1
    vertices = np.vstack(parts_v) @ rotation.T + origin
    return TexturedMesh(
        name=f"speed_bump_{index}", vertices=vertices,
        indices=np.concatenate(tris).astype(np.int32),
        uvs=np.vstack(parts_uv), normals=np.vstack(parts_n) @ rotation.T,
        texture=bump_texture(bump),
    )


def build_speed_bumps(road_map: RoadMap) -> list[tuple[BumpPlacement, TexturedMesh]]:
    """Each bump of the map with its visual mesh, in station order."""
    return [(b, bump_mesh(b, i)) for i, b in enumerate(layout_speed_bumps(road_map))]
