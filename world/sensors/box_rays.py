"""Rays against oriented boxes in closed form (the slab test), for the moving bodies.

For a box of half extents h at `centre` with `rotation` R (box -> world), a ray o + t d is
taken into the box frame (o' = R^T (o - c), d' = R^T d); along each axis it is inside the
slab |x| <= h between t = (-h - o') / d' and (h - o') / d'. The ray is in the box between
the largest entry and the smallest exit; it hits when that span is not empty and its entry
lies in [0, reach]: the hit is at the entry. A ray parallel to a slab is inside it for all t
or for none. A ray starting inside a box is not counted as hitting it (`nearest_box_hits`);
`rays_through` counts it as passing through (a broad phase: what is inside the box may still
be ahead of it).

Rays are only tested against a box when they point within its bounding sphere's cone seen
from the origin, so the cost grows with the rays near a box, not with all rays x all boxes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
IndexArray = NDArray[np.int64]


@dataclass(frozen=True, slots=True, eq=False)
class OrientedBox:
    centre: FloatArray  # (3,) [m] world frame
    rotation: FloatArray  # (3, 3) box -> world
    half_extents: FloatArray  # (3,) [m]


def nearest_box_hits(origin: FloatArray, directions: FloatArray, reach: float,
                     boxes: list[OrientedBox]) -> tuple[FloatArray, NDArray[np.int32]]:
    """Per unit ray (directions (N, 3), world frame) from one `origin` (3,) [m]: the distance
    [m] to the nearest box entry within `reach` [m] (+inf: none), and that box's index in
    `boxes` (-1: none). Equal distances keep the first box."""
    t_best = np.full(len(directions), np.inf)
    which = np.full(len(directions), -1, dtype=np.int32)
    for i, box in enumerate(boxes):
        near = _in_cone(origin, directions, reach, box)
        if not len(near):
            continue
        entry, leave = _slab_span(origin, directions[near], box)
        hit = (entry <= leave) & (entry >= 0.0) & (entry <= reach)
        t = np.where(hit, entry, np.inf)
        closer = t < t_best[near]
        t_best[near[closer]] = t[closer]
        which[near[closer]] = i
    return t_best, which


def rays_through(origin: FloatArray, directions: FloatArray, reach: float,
                 box: OrientedBox) -> tuple[IndexArray, FloatArray]:
    """The rays (indices into `directions` (N, 3), unit, world frame, from `origin` (3,) [m])
    that pass through `box` within [0, reach] [m], those starting inside it included, and
    where each enters it [m] (0 for a ray starting inside)."""
    near = _in_cone(origin, directions, reach, box)
    if not len(near):
        return near, np.zeros(0)
    entry, leave = _slab_span(origin, directions[near], box)
    entry = np.maximum(entry, 0.0)
    through = (entry <= leave) & (entry <= reach)
    return near[through], entry[through]


def _in_cone(origin: FloatArray, directions: FloatArray, reach: float,
             box: OrientedBox) -> IndexArray:
    """The rays pointing within the cone of `box`'s bounding sphere seen from `origin` (all
    of them when the origin is inside the sphere; none when the sphere is out of reach)."""
    to_centre = box.centre - origin
    distance = float(np.linalg.norm(to_centre))
    radius = float(np.linalg.norm(box.half_extents))
    if distance - radius > reach:
        return np.zeros(0, dtype=np.int64)
    if distance > radius:
        return np.flatnonzero(directions @ to_centre
                              >= distance * math.sqrt(1.0 - (radius / distance) ** 2))
    return np.arange(len(directions))


def _slab_span(origin: FloatArray, directions: FloatArray,
               box: OrientedBox) -> tuple[FloatArray, FloatArray]:
    """[m] where each ray enters and leaves the box's three slabs (the ray is in the box
    between them when entry <= leave)."""
    o = (origin - box.centre) @ box.rotation  # box frame (R^T (o - c))
    d = directions @ box.rotation
    h = box.half_extents
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (-h - o) / d
        t2 = (h - o) / d
    # parallel to a slab: inside it always (-inf, +inf) or never (+inf, -inf)
    parallel = d == 0.0
    inside = np.abs(o) <= h
    lo = np.where(parallel, np.where(inside, -np.inf, np.inf), np.minimum(t1, t2))
    hi = np.where(parallel, np.where(inside, np.inf, -np.inf), np.maximum(t1, t2))
    return lo.max(axis=1), hi.min(axis=1)
