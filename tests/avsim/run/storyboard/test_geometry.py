"""Distances between boxes: the rectangle distance against a dense sampling, and the
route distances with and without freespace."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from avsim.run.storyboard import geometry as g
from tests.avsim.run.storyboard.helpers import entity
from world.map.rectangles import rectangle

coord = st.floats(-10.0, 10.0)
size = st.floats(0.2, 6.0)
angle = st.floats(-math.pi, math.pi)
rectangles = st.builds(rectangle, coord, coord, angle, size, size)


def _sampled_distance(a: np.ndarray, b: np.ndarray, n: int = 60) -> tuple[float, bool]:
    """The smallest distance between points sampled densely over both rectangles (their
    areas), and whether a sample of one lies inside the other."""
    k = np.linspace(0.0, 1.0, n)
    u, v = np.meshgrid(k, k)

    def points(r: np.ndarray) -> np.ndarray:
        grid = r[1] + u[..., None] * (r[0] - r[1]) + v[..., None] * (r[2] - r[1])
        return np.asarray(grid, dtype=float).reshape(-1, 2)

    def inside(p: np.ndarray, r: np.ndarray) -> np.ndarray:
        e1, e2 = r[0] - r[1], r[2] - r[1]
        q = p - r[1]
        a1, a2 = q @ e1 / (e1 @ e1), q @ e2 / (e2 @ e2)
        return np.asarray((a1 >= 0) & (a1 <= 1) & (a2 >= 0) & (a2 <= 1), dtype=bool)

    pa, pb = points(a), points(b)
    overlap = bool(inside(pa, b).any() or inside(pb, a).any())
    edges_a = np.concatenate([pa[:n], pa[-n:], pa[::n], pa[n - 1::n]])
    edges_b = np.concatenate([pb[:n], pb[-n:], pb[::n], pb[n - 1::n]])
    d = np.min(np.hypot(*(edges_a[:, None, :] - edges_b[None, :, :]).transpose(2, 0, 1)))
    return float(d), overlap


@settings(max_examples=150, deadline=None)
@given(rectangles, rectangles)
def test_rectangle_distance_is_symmetric_and_non_negative(a: np.ndarray, b: np.ndarray) -> None:
    d = g.rectangle_distance(a, b)
    assert d >= 0.0
    assert math.isclose(d, g.rectangle_distance(b, a), abs_tol=1e-9)


@settings(max_examples=150, deadline=None)
@given(rectangles, rectangles)
@example(rectangle(0.0, 2.0, 0.0, 1.0, 2.0),  # touching, 2.2e-16 m apart by rounding
         rectangle(0.0, -2.220446049250313e-16, 0.0, 1.0, 2.0))
def test_rectangle_distance_matches_a_dense_sampling(a: np.ndarray, b: np.ndarray) -> None:
    d = g.rectangle_distance(a, b)
    sampled, overlap = _sampled_distance(a, b)
    step = 6.0 / 59 * 2  # the sampling's coarseness (largest side / (n - 1), both boxes)
    if overlap:  # a sample on the other's edge counts as inside: touching boxes whose
        #   edges differ by a rounding (2.2e-16 m) are a distance of that rounding apart
        assert d <= 1e-12
    elif d == 0.0:
        assert sampled <= step  # touching, or overlapping between the samples
    else:
        assert d <= sampled + 1e-9
        assert sampled <= d + step


def test_rectangle_distance_of_rotated_boxes() -> None:
    square = rectangle(0.0, 0.0, 0.0, 2.0, 2.0)
    diamond = rectangle(3.0, 0.0, math.pi / 4, 2.0, 2.0)  # its corner at x = 3 - sqrt 2
    assert math.isclose(g.rectangle_distance(square, diamond), 2.0 - math.sqrt(2.0))
    overlapping = rectangle(1.5, 0.0, math.pi / 4, 2.0, 2.0)
    assert g.rectangle_distance(square, overlapping) == 0.0
    inside = rectangle(0.0, 0.0, 0.3, 0.5, 0.5)
    assert g.rectangle_distance(square, inside) == 0.0


def test_longitudinal_and_lateral() -> None:
    a = entity("A", x=0.0)  # box centre at 1.5, length 4: spans -0.5 .. 3.5
    b = entity("B", x=20.0, y=3.0)  # spans 19.5 .. 23.5, width 2 at offset 3
    assert g.longitudinal(a, b, freespace=False) == 20.0
    assert g.longitudinal(a, b, freespace=True) == 16.0
    assert g.longitudinal(b, a, freespace=True) == -16.0
    assert g.lateral(a, b, freespace=False) == 3.0
    assert g.lateral(a, b, freespace=True) == 1.0
    assert g.longitudinal(a, entity("C", x=2.0), freespace=True) == 0.0  # overlapping: 0


def test_cartesian() -> None:
    a, b = entity("A", x=0.0), entity("B", x=20.0, y=3.0)
    assert math.isclose(g.cartesian(a, b, freespace=False), math.hypot(20.0, 3.0))
    assert math.isclose(g.cartesian(a, b, freespace=True), math.hypot(16.0, 1.0))
