"""The trajectory shapes sampled to polylines, against closed forms: a clothoid's end point
and heading (Fresnel integrals), a circle arc, a clothoid spline's joints, a rational
quadratic NURBS quarter circle (exact radius), and a point along a trajectory."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import fresnel

from avsim.scenario.openscenario.positions import Position, WorldPosition
from avsim.scenario.openscenario.resolve import Pose, PositionError
from avsim.scenario.openscenario.sampling import SAMPLE_STEP, clothoid_points, sample
from avsim.scenario.openscenario.trajectories import (
    Clothoid,
    ClothoidSpline,
    ClothoidSplineSegment,
    ControlPoint,
    Nurbs,
    Polyline,
    Vertex,
)


def place(p: Position) -> Pose:
    assert isinstance(p, WorldPosition)
    return Pose(p.x, p.y, p.h or 0.0)


def world(x: float, y: float, h: float = 0.0) -> WorldPosition:
    return WorldPosition(x, y, None, h, None, None)


def test_a_pure_clothoid_ends_where_the_fresnel_integrals_say() -> None:
    rate, length = 0.004, 40.0  # [1/m^2], [m]: from straight to 0.16 1/m
    x, y, h = clothoid_points(Pose(0.0, 0.0, 0.0), 0.0, rate, length)
    a = math.sqrt(math.pi / rate)  # x = a C(L / a), y = a S(L / a) for k(l) = pi l / a^2
    s_end, c_end = fresnel(length / a)
    assert x[-1] == pytest.approx(a * c_end, abs=1e-6)
    assert y[-1] == pytest.approx(a * s_end, abs=1e-6)
    assert h[-1] == pytest.approx(0.5 * rate * length**2, abs=1e-12)
    assert np.max(np.hypot(np.diff(x), np.diff(y))) <= SAMPLE_STEP + 1e-9


def test_a_constant_curvature_clothoid_is_a_circle_arc_from_its_start_pose() -> None:
    k, length, h0 = 0.05, 30.0, 0.7
    shape = Clothoid(k, 0.0, length, 2.0, 5.0, world(10.0, -3.0, h0))
    out = sample(shape, place)
    r = 1.0 / k
    cx, cy = 10.0 - r * math.sin(h0), -3.0 + r * math.cos(h0)  # the centre, to the left
    assert np.allclose(np.hypot(out.x - cx, out.y - cy), r, atol=1e-7)
    end = h0 + k * length
    assert out.x[-1] == pytest.approx(cx + r * math.sin(end), abs=1e-7)
    assert out.y[-1] == pytest.approx(cy - r * math.cos(end), abs=1e-7)
    assert out.times is not None
    assert (out.times[0], out.times[-1]) == pytest.approx((2.0, 5.0))
    assert out.arc[-1] == pytest.approx(length, abs=1e-3)


def test_a_clothoid_without_a_position_starts_at_the_actors_pose() -> None:
    shape = Clothoid(0.0, 0.0, 10.0, None, None, None)
    out = sample(shape, place, Pose(1.0, 2.0, math.pi / 2))
    assert (out.x[-1], out.y[-1]) == pytest.approx((1.0, 12.0))
    assert out.times is None
    with pytest.raises(PositionError, match="no start"):
        sample(shape, place)


def test_a_clothoid_spline_joins_its_segments_and_times_them() -> None:
    segments = (
        ClothoidSplineSegment(0.0, 0.0, 10.0, 0.0, 0.0, world(0.0, 0.0)),
        ClothoidSplineSegment(0.0, 0.1, 10.0, 0.0, 1.0, None),
        ClothoidSplineSegment(0.1, 0.1, 5.0, 0.0, 2.0, None),
    )
    out = sample(ClothoidSpline(segments, 4.0), place)
    assert out.arc[-1] == pytest.approx(25.0, abs=1e-3)
    assert np.all(np.diff(out.arc) > 0.0)  # no repeated joint points
    x2, y2, h2 = clothoid_points(Pose(10.0, 0.0, 0.0), 0.0, 0.01, 10.0)
    x3, y3, _ = clothoid_points(Pose(float(x2[-1]), float(y2[-1]), float(h2[-1])), 0.1, 0.0, 5.0)
    assert (out.x[-1], out.y[-1]) == pytest.approx((x3[-1], y3[-1]), abs=1e-9)
    assert out.times is not None
    assert out.times[-1] == pytest.approx(4.0)
    i = int(np.argmin(np.abs(out.arc - 10.0)))
    assert out.times[i] == pytest.approx(1.0)


def test_a_spline_segment_with_a_heading_offset_turns_at_its_start() -> None:
    segments = (ClothoidSplineSegment(0.0, 0.0, 10.0, math.pi / 2, None, world(0.0, 0.0)),)
    out = sample(ClothoidSpline(segments, None), place)
    assert (out.x[-1], out.y[-1]) == pytest.approx((0.0, 10.0), abs=1e-9)
    assert out.times is None


def test_a_rational_quadratic_nurbs_is_an_exact_quarter_circle() -> None:
    r = 7.0
    w = math.sqrt(0.5)
    points = (ControlPoint(0.0, 1.0, world(r, 0.0)), ControlPoint(1.0, w, world(r, r)),
              ControlPoint(2.0, 1.0, world(0.0, r)))
    out = sample(Nurbs(3, points, (0.0, 0.0, 0.0, 1.0, 1.0, 1.0)), place)
    assert np.allclose(np.hypot(out.x, out.y), r, atol=1e-9)
    assert (out.x[0], out.y[0]) == pytest.approx((r, 0.0))
    assert (out.x[-1], out.y[-1]) == pytest.approx((0.0, r), abs=1e-9)
    assert out.arc[-1] == pytest.approx(0.5 * math.pi * r, rel=1e-3)
    assert out.times is not None
    assert (out.times[0], out.times[-1]) == pytest.approx((0.0, 2.0), abs=1e-9)


def test_a_point_along_a_trajectory_and_off_it() -> None:
    line = Polyline((Vertex(None, world(0.0, 0.0)), Vertex(None, world(0.0, 10.0))))
    out = sample(line, place)
    pose = out.at(4.0, 1.0)  # 4 m up, 1 m to the left (-x)
    assert (pose.x, pose.y, pose.heading) == pytest.approx((-1.0, 4.0, math.pi / 2))
    with pytest.raises(PositionError, match="off the trajectory"):
        out.at(10.5, 0.0)
