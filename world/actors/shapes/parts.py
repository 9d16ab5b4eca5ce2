"""A body's part: one convex solid, where it sits in the body frame, and its material.

The solid is a `world.scene.solids` shape (`Box`, `Cylinder` or `ConvexHull`), all convex, so
that every part can be a Bullet convex shape (a kinematic body cannot carry a concave mesh)
and the LiDAR casters, the contacts and the cameras see the same solid. The part's shape
frame sits at `position` [m] in the body frame, rotated by `orientation` (a unit quaternion
x, y, z, w, as PyBullet takes it); only cylinders are rotated (a wheel's axis is the body's
y, a cylinder's own axis is its z), boxes and hulls are given in body axes.

`points` gives each part as a point set in the body frame: a box's 8 corners, a cylinder's
two rims of `CYLINDER_SIDES` corners on the circle (a multiple of 4, so that the extreme
points along the rims' axes are exactly at the radius: a wheel's lowest point is exactly on
the ground), a hull's own points.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from world.actors.shapes.materials import MATERIALS
from world.scene.solids import Box, ConvexHull, Cylinder, FloatArray, Vec3, quaternion_matrix

Solid = Box | Cylinder | ConvexHull
Quaternion = tuple[float, float, float, float]  # x, y, z, w

IDENTITY: Quaternion = (0.0, 0.0, 0.0, 1.0)
AXIS_Y: Quaternion = (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))  # -90 deg about x: z -> y
AXIS_X: Quaternion = (0.0, math.sqrt(0.5), 0.0, math.sqrt(0.5))  # +90 deg about y: z -> x
CYLINDER_SIDES = 16  # [-] corners of a cylinder's rim in its point set and mesh


@dataclass(frozen=True, slots=True)
class BodyPart:
    """One convex part of a body."""

    name: str  # unique within the body (a mesh group's name)
    solid: Solid
    material: str  # a key of `MATERIALS`
    position: Vec3 = (0.0, 0.0, 0.0)  # [m] the solid's frame in the body frame
    orientation: Quaternion = IDENTITY  # the solid's frame -> body frame

    def __post_init__(self) -> None:
        if self.material not in MATERIALS:
            raise ValueError(f"part {self.name!r}: unknown material {self.material!r}")


def local_points(solid: Solid) -> FloatArray:
    """(P, 3) [m] the solid's points in its own frame."""
    if isinstance(solid, Box):
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)],
                           dtype=np.float64)
        return np.asarray(corners * np.asarray(solid.half_extents), dtype=np.float64)
    if isinstance(solid, Cylinder):
        angle = 2.0 * math.pi * np.arange(CYLINDER_SIDES) / CYLINDER_SIDES
        ring = solid.radius * np.column_stack([np.cos(angle), np.sin(angle)])
        ring[np.abs(ring) < 1e-15] = 0.0
        half = 0.5 * solid.height
        return np.vstack([np.column_stack([ring, np.full(CYLINDER_SIDES, -half)]),
                          np.column_stack([ring, np.full(CYLINDER_SIDES, half)])])
    return np.asarray(solid.points, dtype=np.float64)


def points(part: BodyPart) -> FloatArray:
    """(P, 3) [m] the part's points in the body frame."""
    turned = local_points(part.solid) @ quaternion_matrix(part.orientation).T
    moved = turned + np.asarray(part.position)
    return np.asarray(moved, dtype=np.float64)


def box(name: str, material: str, lo: Vec3, hi: Vec3) -> BodyPart:
    """An axis-aligned box from corner `lo` to corner `hi` [m] (body frame)."""
    half = tuple(0.5 * (h - low) for low, h in zip(lo, hi, strict=True))
    centre = tuple(0.5 * (h + low) for low, h in zip(lo, hi, strict=True))
    return BodyPart(name, Box((half[0], half[1], half[2])), material,
                    (centre[0], centre[1], centre[2]))


def hull(name: str, material: str, pts: FloatArray | list[Vec3]) -> BodyPart:
    """The convex hull of `pts` (P, 3) [m] (body frame), its frame at their bounding-box
    centre (so that the hull's points stay small numbers near the origin)."""
    p = np.asarray(pts, dtype=np.float64)
    centre = 0.5 * (p.min(axis=0) + p.max(axis=0))
    return BodyPart(name, ConvexHull(p - centre), material,
                    (float(centre[0]), float(centre[1]), float(centre[2])))


def mirrored(pts: list[Vec3]) -> list[Vec3]:
    """`pts` and their mirror images across the body's centre plane y = 0."""
    return [*pts, *((x, -y, z) for x, y, z in pts)]


def wheel(name: str, x: float, y: float, radius: float, width: float) -> BodyPart:
    """A tyre: a cylinder of `radius` [m] and `width` [m] about the body's y axis, its centre
    at (x, y) [m] and at the height of its radius (standing on the ground)."""
    return BodyPart(name, Cylinder(radius, width), "tyre", (x, y, radius), AXIS_Y)


def strut(name: str, material: str, a: Vec3, b: Vec3, radius: float,
          sides: int = 6) -> BodyPart:
    """A prism of `sides` sides around the segment `a` -> `b` [m], of circumradius `radius`
    [m]: a tube, a limb. The prism's corners sit on the circle."""
    pa, pb = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    axis = (pb - pa) / np.linalg.norm(pb - pa)
    helper = np.array([0.0, 0.0, 1.0]) if abs(axis[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(axis, helper)
    u /= np.linalg.norm(u)
    v = np.cross(axis, u)
    angle = 2.0 * math.pi * (np.arange(sides) + 0.5) / sides
    ring = radius * (np.outer(np.cos(angle), u) + np.outer(np.sin(angle), v))
    return hull(name, material, np.vstack([pa + ring, pb + ring]))
