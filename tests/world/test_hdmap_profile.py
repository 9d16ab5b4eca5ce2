"""The HD map's lanes whose widths change along a segment (a `LaneProfile`: every boundary a
cubic in the segment's station), and the uniform sections' numbers, which are the same as
ever bit for bit."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from numpy.typing import NDArray

from tests.roads import SHOULDER, W, make_map, numeric_curvature, seg
from world.hdmap import SHOULDER as SHOULDER_LANE
from world.hdmap import CrossSection, LaneProfile, RoadMap, Zone
from world.map.road import MapError
from world.spec import SegmentSpec

STATIONS = np.linspace(-30.0, 430.0, 4601)  # [m] beyond both ends too


def uniform_road() -> RoadMap:
    """Three segments of different layouts: 2 + 1 lanes, 3 + 0 lanes on a left arc, 1 + 2
    lanes on a right arc without a shoulder."""
    return make_map(seg(120.0, lanes=2, oncoming=1), seg(150.0, 300.0, lanes=3, oncoming=0),
                    dataclasses.replace(seg(130.0, -250.0, lanes=1, oncoming=2),
                                        lane_width=3.25, shoulder=0.0))


def test_uniform_sections_give_the_old_numbers_bit_for_bit() -> None:
    """Offsets, widths, paved edges, curvatures and lane bands by the uniform rules, the
    same floating-point expressions as before lane profiles existed (`==`, not approx)."""
    m = uniform_road()
    seg_i = m.line.segment_index(STATIONS)
    w = np.array([c.lane_width for c in m.sections])[seg_i]
    lanes = np.array([c.lanes for c in m.sections])[seg_i]
    shoulder = np.array([c.shoulder for c in m.sections])[seg_i]
    onc = np.array([c.oncoming_lanes for c in m.sections])[seg_i]
    k = m.line.curvature(STATIONS)
    for lane in m.lanes:
        off = lane.index * w
        assert np.array_equal(lane.offset_at(STATIONS), off)
        assert np.array_equal(lane.width_at(STATIONS), w)
        assert np.array_equal(lane.curvature_at(STATIONS), k / (1.0 - k * off))
    for j, lane in enumerate(m.oncoming, start=1):
        assert np.array_equal(lane.offset_at(STATIONS), (lanes + j - 1) * w)
    assert np.array_equal(m.shoulder.offset_at(STATIONS), -0.5 * (w + shoulder))
    assert np.array_equal(m.shoulder.width_at(STATIONS), shoulder)
    right, left = m.paved_edges(STATIONS)
    assert np.array_equal(right, -(0.5 * w + shoulder))
    assert np.array_equal(left, (lanes + onc - 0.5) * w)
    assert np.array_equal(m.centre_line_at(STATIONS), (lanes - 0.5) * w)
    for s, d in zip(STATIONS[::37].tolist(), np.linspace(-3.0, 12.0, 125).tolist(),
                    strict=True):
        c = m.cross_section_at(s)
        index, r = m.lane_of(s, d)
        band = math.floor((d + 0.5 * c.lane_width) / c.lane_width)
        if 0.0 <= s <= m.length and 0 <= band < c.lanes + c.oncoming_lanes:
            assert (index, r) == (band if band < c.lanes else c.lanes - 1 - band,
                                 d - band * c.lane_width)
        b = m.lane_boundaries(s)
        n = c.lanes + c.oncoming_lanes
        assert b.tolist() == [c.right_edge, *((i - 0.5) * c.lane_width for i in range(n + 1))]


# a 2 + 1 lane segment of 100 m whose lane 0 narrows 3.75 -> 3.25 m (a cubic with zero slope
# at both ends), lane 1 a constant 3.5 m beside it, the oncoming lane 3.4 m, a shoulder
# widening 2.0 -> 2.6 m linearly
L = 100.0
TAPER = (3.75, 0.0, 3.0 * -0.5 / L**2, -2.0 * -0.5 / L**3)  # lane 0's width, a b c d


def half(c: tuple[float, ...], sign: float) -> tuple[float, float, float, float]:
    a, b, cc, d = c
    return (sign * 0.5 * a, sign * 0.5 * b, sign * 0.5 * cc, sign * 0.5 * d)


def shifted(c: tuple[float, float, float, float],
            by: float) -> tuple[float, float, float, float]:
    return (c[0] + by, c[1], c[2], c[3])


RIGHT0 = half(TAPER, -1.0)
LEFT0 = half(TAPER, 1.0)
CENTRE = shifted(LEFT0, 3.5)
PROFILE = LaneProfile((
    (RIGHT0[0] - 2.0, RIGHT0[1] - 0.006, RIGHT0[2], RIGHT0[3]),  # the shoulder's outer edge
    RIGHT0, LEFT0, CENTRE, shifted(CENTRE, 3.4)))


def taper(u: NDArray[np.float64]) -> NDArray[np.float64]:
    x = np.clip(u, 0.0, L) / L
    out: NDArray[np.float64] = 3.75 - 0.5 * x * x * (3.0 - 2.0 * x)
    return out


def profiled_road(radius: float = 0.0) -> RoadMap:
    """A uniform 50 m, the profiled 100 m (a straight or an arc), a uniform 50 m."""
    varying = dataclasses.replace(seg(L, radius, lanes=2, oncoming=1), lane_width=3.75,
                                  shoulder=2.0, profile=PROFILE)
    return make_map(seg(50.0), varying, dataclasses.replace(seg(50.0), lane_width=3.25))


def test_a_profiled_segments_lanes_are_its_cubics() -> None:
    m = profiled_road()
    s = np.linspace(50.0, 150.0, 1001)[:-1]  # 150 m belongs to the next segment
    u = s - 50.0
    assert np.array_equal(m.lane(0).offset_at(s), np.zeros_like(s))  # exactly the line
    np.testing.assert_allclose(m.lane(0).width_at(s), taper(u), atol=1e-12)
    np.testing.assert_allclose(m.lane(1).width_at(s), 3.5, atol=1e-12)
    np.testing.assert_allclose(m.lane(1).offset_at(s), 0.5 * taper(u) + 1.75, atol=1e-12)
    np.testing.assert_allclose(m.lane(-1).width_at(s), 3.4, atol=1e-12)
    np.testing.assert_allclose(m.lane(-1).offset_at(s), 0.5 * taper(u) + 5.2, atol=1e-12)
    np.testing.assert_allclose(m.lane(SHOULDER_LANE).width_at(s), 2.0 + 0.006 * u, atol=1e-12)
    np.testing.assert_allclose(m.lane(SHOULDER_LANE).offset_at(s),
                               -0.5 * taper(u) - 0.5 * (2.0 + 0.006 * u), atol=1e-12)
    right, left = m.paved_edges(s)
    np.testing.assert_allclose(right, -0.5 * taper(u) - 2.0 - 0.006 * u, atol=1e-12)
    np.testing.assert_allclose(left, 0.5 * taper(u) + 6.9, atol=1e-12)
    np.testing.assert_allclose(m.centre_line_at(s), 0.5 * taper(u) + 3.5, atol=1e-12)
    b = np.array([m.lane_boundaries(float(x)) for x in s])
    assert np.all(np.diff(b, axis=1) > 0.0)
    np.testing.assert_allclose(b, m.segment_boundaries(1, s), atol=0.0)


def test_the_uniform_neighbours_keep_their_numbers() -> None:
    m = profiled_road()
    assert float(m.lane(1).offset_at(25.0)) == W and float(m.lane(1).offset_at(175.0)) == 3.25
    assert float(m.lane(0).width_at(49.999)) == W
    assert float(m.lane(0).width_at(150.0)) == 3.25
    assert float(m.lane(0).width_at(149.999)) == pytest.approx(3.25, abs=1e-9)
    assert float(m.shoulder.width_at(20.0)) == SHOULDER


def test_lane_of_uses_the_boundaries_where_they_lie() -> None:
    m = profiled_road()
    s = 130.0
    b = m.lane_boundaries(s)
    for band, index in enumerate((0, 1, -1)):
        for d in (b[band + 1] + 1e-6, 0.5 * (b[band + 1] + b[band + 2]), b[band + 2] - 1e-6):
            lane, r = m.lane_of(s, float(d))
            assert lane == index
            assert r == pytest.approx(float(d) - float(m.lane(index).offset_at(s)), abs=1e-12)
    assert m.lane_of(s, float(b[1]) - 1e-6) == (None, float(b[1]) - 1e-6)
    assert m.lane_of(s, float(b[-1]) + 1e-6)[0] is None


@pytest.mark.parametrize("radius", [0.0, 120.0, -90.0])
def test_lane_curvature_is_exact_where_the_offset_varies(radius: float) -> None:
    """A varying lane's centre-line curvature against the turn of its heading (finite
    differences of its points)."""
    m = profiled_road(radius)
    lane = m.lane(1)
    for s in (60.0, 85.0, 100.0, 140.0):
        numeric = numeric_curvature(lane, s)
        assert float(lane.curvature_at(s)) == pytest.approx(numeric, abs=2e-6), s
    if radius == 0.0:  # a straight's lane bends where its offset does (k / a would be 0)
        assert abs(float(lane.curvature_at(60.0))) > 1e-4


def test_a_constant_profile_is_the_uniform_layout() -> None:
    """A profile with b = c = d = 0 at the uniform places gives the uniform numbers (to
    rounding: (k - 1/2) w against i w)."""
    uniform = make_map(seg(100.0, 200.0))
    c = uniform.sections[0]
    profile = LaneProfile(tuple((float(a), 0.0, 0.0, 0.0)
                                for a in c.boundary_cubics()[:, 0]))
    profiled = make_map(dataclasses.replace(seg(100.0, 200.0), profile=profile))
    s = np.linspace(0.0, 100.0, 101)
    for index in (0, 1, -1, SHOULDER_LANE):
        a, b = uniform.lane(index), profiled.lane(index)
        np.testing.assert_allclose(b.offset_at(s), a.offset_at(s), atol=1e-12)
        np.testing.assert_allclose(b.width_at(s), a.width_at(s), atol=1e-12)
        np.testing.assert_allclose(b.curvature_at(s), a.curvature_at(s), atol=1e-15)


def test_a_profile_needs_one_boundary_per_lane_edge() -> None:
    with pytest.raises(ValueError, match="needs 5 boundaries, got 2"):
        CrossSection(2, 1, 3.5, 0.0, Zone.HIGHWAY, None,
                     LaneProfile(((0.0, 0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))))


def test_an_arc_too_tight_for_a_widening_edge_raises_map_error() -> None:
    """The inner edge's largest offset along the segment counts, not its start's."""
    wide = LaneProfile(((-4.0, 0.0, 0.0, 0.0), (-1.75, 0.0, 0.0, 0.0), (1.75, 0.0, 0.0, 0.0),
                        (5.25, 0.0, 0.0, 0.0), (8.75, 0.15, 0.0, 0.0)))  # 13.25 m at 30 m
    spec = SegmentSpec(length=30.0, curvature=1.0 / 12.0, lanes=2, oncoming_lanes=1,
                       lane_width=3.5, shoulder=2.25, profile=wide)
    with pytest.raises(MapError, match="left"):
        make_map(spec)
