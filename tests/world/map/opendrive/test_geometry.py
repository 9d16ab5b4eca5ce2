"""The exact reference-line geometry: each planView shape against closed forms and numerical
integration, continuity across records, projection round trips."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq
from scipy.special import fresnel

from world.map.opendrive import (
    Arc,
    Geometry,
    Line,
    ParamPoly3,
    PlanView,
    Poly3Shape,
    Shape,
    Spiral,
    load_opendrive,
)

DATA = Path(__file__).parent / "data"
ALKS = sorted(
    (Path(__file__).parents[4] / "tests/data/alks/logical_scenarios/concrete_scenarios")
    .joinpath("road_networks")
    .glob("*.xodr")
)


def one(shape: Shape, length: float, x: float = 0.0, y: float = 0.0, hdg: float = 0.0) -> PlanView:
    return PlanView((Geometry(0.0, x, y, hdg, length, shape),))


def integrated(k0: float, k1: float, length: float, s: np.ndarray) -> np.ndarray:
    """x, y, heading of the clothoid by integrating the heading numerically (DOP853)."""
    rate = (k1 - k0) / length

    def f(si: float, z: np.ndarray) -> list[float]:
        return [np.cos(z[2]), np.sin(z[2]), k0 + rate * si]

    sol = solve_ivp(
        f, (0.0, length), [0.0, 0.0, 0.0], method="DOP853", t_eval=s, rtol=1e-13, atol=1e-13
    )
    return np.asarray(sol.y)


def test_line_pose_and_extensions() -> None:
    pv = one(Line(), 10.0, 1.0, 2.0, np.pi / 3)
    x, y, h = pv.pose(np.array([-2.0, 0.0, 4.0, 10.0, 15.0]))
    d = np.array([-2.0, 0.0, 4.0, 10.0, 15.0])
    assert np.allclose(x, 1 + d * np.cos(np.pi / 3), atol=1e-12)
    assert np.allclose(y, 2 + d * np.sin(np.pi / 3), atol=1e-12)
    assert np.allclose(h, np.pi / 3)
    assert pv.length == 10.0
    assert np.all(pv.curvature(d) == 0.0)


@pytest.mark.parametrize("k", [0.02, -0.05, 1e-9, 0.0])
def test_arc_closed_form(k: float) -> None:
    s = np.linspace(0.0, 60.0, 13)
    x, y, h = one(Arc(k), 60.0).pose(s)
    if k == 0.0:
        assert np.allclose(x, s) and np.allclose(y, 0.0)
        return
    r = 1 / k  # centre (0, r): the point at angle k s
    assert np.allclose(x, r * np.sin(k * s), atol=1e-9)
    assert np.allclose(y, 2 * r * np.sin(k * s / 2) ** 2, atol=1e-9)
    assert np.allclose(h, k * s)
    assert np.allclose(one(Arc(k), 60.0).curvature(s), k)


def test_clothoid_from_zero_matches_fresnel_closed_form() -> None:
    k1, length = 0.04, 80.0
    s = np.linspace(0.0, length, 41)
    x, y, h = one(Spiral(0.0, k1), length).pose(s)
    scale = np.sqrt(np.pi * length / k1)  # heading k1 s^2 / (2 L) = pi/2 (s/scale)^2
    fs, fc = fresnel(s / scale)
    assert np.max(np.abs(x - scale * fc)) < 1e-10
    assert np.max(np.abs(y - scale * fs)) < 1e-10
    assert np.allclose(h, k1 * s**2 / (2 * length), atol=1e-14)


@pytest.mark.parametrize(
    ("k0", "k1", "length"),
    [
        (0.0, 0.04, 80.0),
        (0.01, 0.03, 50.0),  # nonzero curvStart
        (-0.004, 0.0, 100.0),  # negative, to zero
        (-0.01, -0.05, 40.0),  # negative both
        (0.02, -0.03, 60.0),  # through zero
        (0.2, 0.01, 30.0),  # tight
        (0.01, 0.01 + 1e-8, 200.0),  # ill-conditioned for Fresnel: quadrature
        (0.05, 0.05 + 1e-14, 100.0),  # rate 0: the arc
    ],
)
def test_spiral_matches_numerical_integration(k0: float, k1: float, length: float) -> None:
    s = np.linspace(0.0, length, 21)
    pv = one(Spiral(k0, k1), length)
    x, y, h = pv.pose_unwrapped(s)
    ref = integrated(k0, k1, length, s)
    assert np.max(np.hypot(x - ref[0], y - ref[1])) < 1e-8
    assert np.max(np.abs(h - ref[2])) < 1e-10
    assert np.allclose(pv.curvature(s), k0 + (k1 - k0) * s / length)


def test_spiral_without_rate_is_the_arc() -> None:
    s = np.linspace(0.0, 50.0, 11)
    a = np.stack(one(Spiral(0.03, 0.03), 50.0).pose(s))
    b = np.stack(one(Arc(0.03), 50.0).pose(s))
    assert np.allclose(a, b, atol=1e-12)


def test_poly3_parabola_arc_length() -> None:
    c, u1 = 0.01, 50.0

    def arc(u: np.ndarray) -> np.ndarray:  # arc length of v = c u^2 from 0 to u
        w = 2 * c * u
        return np.asarray((w * np.sqrt(1 + w * w) + np.arcsinh(w)) / (4 * c))

    length = float(arc(np.array(u1)))
    pv = one(Poly3Shape(0.0, 0.0, c, 0.0), length, hdg=0.0)
    u = np.linspace(0.0, u1, 26)
    x, y, h = pv.pose(arc(u))
    assert np.max(np.abs(x - u)) < 1e-9
    assert np.max(np.abs(y - c * u**2)) < 1e-9
    assert np.allclose(h, np.arctan(2 * c * u), atol=1e-12)
    assert np.allclose(pv.curvature(arc(u)), 2 * c / (1 + 4 * c * c * u * u) ** 1.5)


def test_param_poly3_straight_lines() -> None:
    s = np.linspace(0.0, 50.0, 11)
    # normalized, uniform speed: p in [0, 1] along (30, 40)
    x, y, h = one(ParamPoly3(0, 30, 0, 0, 0, 40, 0, 0, "normalized"), 50.0).pose(s)
    assert np.allclose(x, 0.6 * s, atol=1e-10) and np.allclose(y, 0.8 * s, atol=1e-10)
    assert np.allclose(h, np.arctan2(4, 3))
    # normalized, nonuniform speed u = 50 p^2: the station is still arc length
    x, y, _ = one(ParamPoly3(0, 0, 50, 0, 0, 0, 0, 0, "normalized"), 50.0).pose(s[1:])
    assert np.allclose(x, s[1:], atol=1e-10) and np.allclose(y, 0.0)
    # arcLength: p in [0, length]
    x, y, _ = one(ParamPoly3(0, 0.6, 0, 0, 0, 0.8, 0, 0, "arcLength"), 50.0).pose(s)
    assert np.allclose(x, 0.6 * s, atol=1e-10) and np.allclose(y, 0.8 * s, atol=1e-10)


def test_param_poly3_quarter_circle() -> None:
    r, kappa = 20.0, 0.5519150244935105  # the cubic Bezier closest to a quarter circle
    p0, p1, p2, p3 = (np.array(p) for p in ([0, 0], [kappa * r, 0], [r, r - kappa * r], [r, r]))
    b, c, d = 3 * (p1 - p0), 3 * (p0 - 2 * p1 + p2), p3 - p0 + 3 * (p1 - p2)
    shape = ParamPoly3(0, b[0], c[0], d[0], 0, b[1], c[1], d[1], "normalized")
    length = np.pi * r / 2
    pv = one(shape, length)
    s = np.linspace(0.0, length, 101)
    x, y, h = pv.pose(s)
    assert np.max(np.abs(np.hypot(x, y - r) - r)) < 2e-4 * r  # on the circle
    assert np.max(np.abs(h - s / r)) < 2e-3  # heading ~ turned angle
    assert abs(x[-1] - r) < 1e-9 and abs(y[-1] - r) < 1e-9  # ends at the Bezier's end
    assert np.allclose(pv.curvature(s), 1 / r, rtol=0.02)


def _joins(path: Path) -> tuple[float, float]:
    worst_xy = worst_h = 0.0
    for road in load_opendrive(path).roads:
        pv = road.plan_view
        for a, b in zip(pv.geometries, pv.geometries[1:], strict=False):
            prev = PlanView((a,))
            x, y, h = prev.pose_unwrapped(np.array([a.s + a.length]))
            worst_xy = max(worst_xy, float(np.hypot(x[0] - b.x, y[0] - b.y)))
            dh = (h[0] - b.hdg + np.pi) % (2 * np.pi) - np.pi
            worst_h = max(worst_h, abs(float(dh)))
    return worst_xy, worst_h


@pytest.mark.parametrize("path", [*ALKS, DATA / "mixed.xodr"], ids=lambda p: p.name)
def test_consecutive_records_join(path: Path) -> None:
    worst_xy, worst_h = _joins(path)
    assert worst_xy < 1e-3
    assert worst_h < 1e-6


def test_pose_is_continuous_across_records() -> None:
    pv = load_opendrive(DATA / "mixed.xodr").road("1").plan_view
    for g in pv.geometries[1:]:
        x, y, h = pv.pose(np.array([g.s - 1e-9, g.s]))
        assert np.hypot(x[1] - x[0], y[1] - y[0]) < 1e-8
        assert abs(h[1] - h[0]) < 1e-8


MIXED = load_opendrive(DATA / "mixed.xodr").road("1").plan_view


@settings(max_examples=200, deadline=None)
@given(s=st.floats(-20.0, MIXED.end + 20.0), t=st.floats(-6.0, 6.0))
def test_project_round_trip(s: float, t: float) -> None:
    x, y, h = MIXED.pose(np.array([s]))
    p = np.array([[x[0] - t * np.sin(h[0]), y[0] + t * np.cos(h[0])]])
    s2, t2 = MIXED.project(p)
    assert abs(s2[0] - s) < 1e-3 and abs(t2[0] - t) < 1e-3


def test_project_vectorised_shape() -> None:
    s = np.linspace(0.0, MIXED.end, 12).reshape(3, 4)
    x, y, _ = MIXED.pose(s)
    s2, t2 = MIXED.project(np.stack([x, y], axis=-1))
    assert s2.shape == (3, 4) and np.allclose(s2, s, atol=1e-6) and np.allclose(t2, 0, atol=1e-6)


def test_param_poly3_turning_past_a_quarter_keeps_its_heading_continuous() -> None:
    r = 10.0
    k = 4 * r / 3
    p0, p1, p2, p3 = (np.array(p) for p in ([0, 0], [k, 0], [k, 2 * r - 0.2 * k], [0, 2 * r]))
    b, c, d = 3 * (p1 - p0), 3 * (p0 - 2 * p1 + p2), p3 - p0 + 3 * (p1 - p2)
    shape = ParamPoly3(0, b[0], c[0], d[0], 0, b[1], c[1], d[1], "normalized")
    pv = one(shape, 30.0, hdg=2.5)  # starts near +pi: the wrapped heading crosses it
    _, _, h = pv.pose_unwrapped(np.linspace(0.0, 30.0, 301))
    assert np.max(np.abs(np.diff(h))) < 0.1
    assert h[-1] == pytest.approx(2.5 + np.pi - np.arctan(0.2))


def _arc_length_inverse(speed: Callable[[float], float], end: float, target: float) -> float:
    """The parameter at which the curve of |dr/dp| `speed` has run `target` [m] of arc
    length from 0 (`end` bounds the parameter)."""
    return float(brentq(lambda p: quad(speed, 0.0, p, epsabs=1e-13, epsrel=1e-13)[0] - target,
                        0.0, end, xtol=1e-14))


def _expected_local(g: Geometry, ds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """u, v [m] of record `g` at stations ds, from closed forms or quadrature written here,
    independent of `world.map.opendrive.shapes`."""
    shape = g.shape
    if isinstance(shape, Line):
        return ds, np.zeros_like(ds)
    if isinstance(shape, Arc):
        k = shape.curvature
        return np.sin(k * ds) / k, (1.0 - np.cos(k * ds)) / k
    if isinstance(shape, Spiral):
        u, v, _ = integrated(shape.curv_start, shape.curv_end, g.length, ds)
        return u, v
    if isinstance(shape, Poly3Shape):  # u such that the arc length of (u, v(u)) is ds
        a, b, c, d = shape.a, shape.b, shape.c, shape.d
        us = np.array([_arc_length_inverse(lambda t: math.hypot(1.0, b + 2 * c * t + 3 * d * t * t),
                                           2.0 * g.length, s) for s in ds])
        return us, a + b * us + c * us**2 + d * us**3
    assert isinstance(shape, ParamPoly3)
    p_end = 1.0 if shape.p_range == "normalized" else g.length

    def speed(p: float) -> float:
        return math.hypot(shape.bu + 2 * shape.cu * p + 3 * shape.du * p * p,
                          shape.bv + 2 * shape.cv * p + 3 * shape.dv * p * p)

    scale = quad(speed, 0.0, p_end, epsabs=1e-13, epsrel=1e-13)[0] / g.length
    ps = np.array([_arc_length_inverse(speed, p_end, s * scale) for s in ds])
    return (shape.au + shape.bu * ps + shape.cu * ps**2 + shape.du * ps**3,
            shape.av + shape.bv * ps + shape.cv * ps**2 + shape.dv * ps**3)


def test_every_record_of_a_file_against_closed_forms_and_quadrature() -> None:
    """mixed.xodr, read from the file: line, arcs, spirals, a poly3 and both paramPoly3
    ranges, each within 1e-6 m of its closed form or of quadrature along it."""
    plan_view = load_opendrive(DATA / "mixed.xodr").road("1").plan_view
    kinds = set()
    for g in plan_view.geometries:
        ds = np.linspace(0.0, g.length, 9)
        u, v = _expected_local(g, ds)
        x = g.x + u * math.cos(g.hdg) - v * math.sin(g.hdg)
        y = g.y + u * math.sin(g.hdg) + v * math.cos(g.hdg)
        px, py, _ = plan_view.pose(g.s + ds)
        assert np.hypot(px - x, py - y).max() < 1e-6, type(g.shape).__name__
        kinds.add(type(g.shape).__name__ + getattr(g.shape, "p_range", ""))
    assert kinds == {"Line", "Arc", "Spiral", "Poly3Shape", "ParamPoly3normalized",
                     "ParamPoly3arcLength"}
