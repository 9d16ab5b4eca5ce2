"""The arc spline of an offset curve ref(s) + t(s) n(s): analytic cases (a constant offset
of an arc is an arc of radius R - t; a linear offset of a straight is a straight at
atan(t')), exact joints, the deviation bound by dense sampling on a spiral with a cubic
offset, and the lane fits' boundaries against their exact crossings."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from world.map.opendrive.arcspline import piece_points
from world.map.opendrive.geometry import PlanView
from world.map.opendrive.lane_fit import cubic_values, fit_boundaries, normal_offsets
from world.map.opendrive.model import Arc, Geometry, Line, Spiral
from world.map.opendrive.offset_spline import (
    CurvePiece,
    OffsetCurve,
    arc_length,
    distance_to_arc,
    offset_arc_spline,
)

TOL = 1e-3  # [m]


def view(shape: Line | Arc | Spiral, length: float = 100.0) -> PlanView:
    return PlanView((Geometry(0.0, 3.0, -2.0, 0.4, length, shape),))


def dense_deviation(curve: OffsetCurve, pieces: list[CurvePiece]) -> float:
    """[m] the largest distance, over 2001 exact samples per piece, from the piece's arc."""
    worst = 0.0
    for p in pieces:
        x, y, _, _ = curve.pose(np.linspace(p.s0, p.s1, 2001))
        worst = max(worst, float(np.max(distance_to_arc(p, x, y))))
    return worst


@pytest.mark.parametrize("t", [-4.5, 0.0, 2.0])
def test_a_constant_offset_of_an_arc_is_an_arc_of_radius_r_minus_t(t: float) -> None:
    radius = 80.0
    curve = OffsetCurve(view(Arc(1.0 / radius)), 0.0, (t,))
    (piece,) = offset_arc_spline(curve, 0.0, 100.0, TOL)
    assert piece.curvature == pytest.approx(1.0 / (radius - t), rel=1e-12)
    assert piece.length == pytest.approx(100.0 * (radius - t) / radius, rel=1e-12)
    assert dense_deviation(curve, [piece]) < 1e-9


def test_a_linear_offset_of_a_straight_is_a_straight_at_atan_slope() -> None:
    slope = 0.03
    curve = OffsetCurve(view(Line()), 0.0, (-1.0, slope))
    (piece,) = offset_arc_spline(curve, 0.0, 100.0, TOL)
    assert piece.curvature == pytest.approx(0.0, abs=1e-15)
    assert piece.heading0 == pytest.approx(0.4 + math.atan(slope), abs=1e-15)
    assert piece.length == pytest.approx(100.0 * math.hypot(1.0, slope), rel=1e-13)
    assert dense_deviation(curve, [piece]) < 1e-9


def test_the_arc_length_is_the_curves() -> None:
    """Gauss-Legendre against a fine trapezoid sum of the chord lengths."""
    curve = OffsetCurve(view(Spiral(0.01, -0.02)), 0.0, (-3.0, 0.01, 2e-4, -2e-6))
    x, y, _, _ = curve.pose(np.linspace(0.0, 100.0, 200001))
    chords = float(np.sum(np.hypot(np.diff(x), np.diff(y))))
    assert arc_length(curve, 0.0, 100.0) == pytest.approx(chords, abs=1e-6)


@pytest.mark.parametrize("tolerance", [1e-2, 1e-3, 1e-4])
def test_a_cubic_offset_of_a_spiral_keeps_within_tolerance(tolerance: float) -> None:
    """Dense sampling bounds the deviation; every joint is an exact sample (position and
    heading of the curve) and the chain is continuous within the tolerance."""
    curve = OffsetCurve(view(Spiral(0.01, -0.02)), 0.0, (-3.0, 0.01, 2e-4, -2e-6))
    pieces = offset_arc_spline(curve, 0.0, 100.0, tolerance)
    assert len(pieces) > 2
    assert dense_deviation(curve, pieces) < tolerance
    for a, b in itertools.pairwise(pieces):
        assert a.s1 == b.s0
        x, y, h, _ = curve.pose(np.array([b.s0]))
        assert (b.x0, b.y0, b.heading0) == pytest.approx((x[0], y[0], h[0]), abs=1e-12)
        ex, ey = piece_points(a.arc(), np.array([a.length]))
        assert math.hypot(ex[0] - b.x0, ey[0] - b.y0) < tolerance
        assert a.heading0 + a.curvature * a.length == pytest.approx(b.heading0, abs=1e-9)


def test_a_boundarys_offset_along_the_route_normal_is_exact() -> None:
    """On a straight with a linear lane-0 offset (the route turned by atan(t0') from the
    file), a border parallel to the file's line at t = 2 is crossed by the route's normal
    at the closed-form distance: (2 - t0(s)) / cos(theta) on the line turned by theta."""
    slope = 0.02
    record = view(Line())
    centre = OffsetCurve(record, 0.0, (-1.0, slope))
    border = OffsetCurve(record, 0.0, (2.0,))
    (piece,) = offset_arc_spline(centre, 0.0, 100.0, TOL)
    u = np.linspace(0.0, piece.length, 11)
    theta = math.atan(slope)
    s = u * math.cos(theta)  # the file station of the route's point at u
    expected = (2.0 - (-1.0 + slope * s)) / math.cos(theta)
    assert normal_offsets(border, piece, u) == pytest.approx(expected, abs=1e-9)


def test_the_fitted_cubics_hold_a_cubic_taper_within_the_fit_budget() -> None:
    """Boundaries of a 3.75 -> 3.25 m taper on an arc: the cubics against the exact
    crossings at 101 stations of the first piece of the centre's spline (at the route's
    0.5 mm): another boundary within the fit's own checked error (the 4 Chebyshev points
    are exact for a cubic, so it is tiny), lane 0's edges (-w/2, +w/2 about the piece)
    within the piece's deviation from the centre + the skew + the fit, < 1 mm."""
    record = view(Arc(1.0 / 300.0))
    d = -0.5
    width = (3.75, 0.0, 3.0 * d / 120.0**2, -2.0 * d / 120.0**3)
    outer = (-3.5 - width[0], *(-w for w in width[1:]))
    inner = (-3.5, 0.0, 0.0, 0.0)
    centre_t = tuple(0.5 * (a + b) for a, b in zip(outer, inner, strict=True))
    centre = OffsetCurve(record, 0.0, centre_t)
    curves = [OffsetCurve(record, 0.0, t) for t in (outer, outer, inner, (0.0,))]
    piece = offset_arc_spline(centre, 40.0, 70.0, 0.5 * TOL)[0]
    coef, error, skew = fit_boundaries(curves, centre, piece)
    u = np.linspace(0.0, piece.length, 101)
    exact = np.array([normal_offsets(c, piece, u) for c in curves])
    fitted = cubic_values(coef, u)
    assert np.max(np.abs(fitted[3] - exact[3])) <= error + 1e-9
    assert error < 1e-6
    assert np.max(np.abs(fitted[1:3] - exact[1:3])) < TOL
    assert skew < 1e-4
    assert coef[1] == pytest.approx(-coef[2], abs=0.0)  # lane 0 centred on its line
