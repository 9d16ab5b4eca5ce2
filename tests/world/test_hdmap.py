"""Tests of the HD map: reference-line geometry, lanes, projections, limits, errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.roads import KPH, SHOULDER, W, arc, make_map, seg
from world.hdmap import RoadMap, SpeedLimitSign, StopSign, Zone
from world.map.road import MapError, build_road_map
from world.spec import RoadSpec


@pytest.fixture
def winding() -> RoadMap:
    """Straights, left and right arcs (one beyond 180 degrees), lane count changes."""
    return make_map(
        seg(100.0),
        arc(50.0, 90.0),
        seg(60.0, lanes=3, oncoming=2),
        arc(-80.0, -60.0),
        seg(40.0, lanes=1, oncoming=0),
        arc(60.0, 200.0, lanes=1, oncoming=1),
        seg(50.0),
    )


def test_known_chain_end_point_and_heading() -> None:
    m = make_map(seg(100.0), arc(50.0, 90.0))
    lane = m.lane(0)
    assert m.length == pytest.approx(100.0 + 25.0 * math.pi)
    np.testing.assert_allclose(lane.position(m.length, 0.0), [150.0, 50.0], atol=1e-9)
    assert float(lane.heading_at(m.length)) == pytest.approx(math.pi / 2, abs=1e-12)
    # halfway round the arc: 45 degrees around the centre (100, 50)
    mid = lane.position(100.0 + 12.5 * math.pi, 0.0)
    np.testing.assert_allclose(
        mid, [100 + 50 * math.sin(math.pi / 4), 50 - 50 * math.cos(math.pi / 4)]
    )


def test_right_arc_end_point_and_lane_radius() -> None:
    m = make_map(seg(100.0), arc(-50.0, -90.0))
    np.testing.assert_allclose(m.lane(0).position(m.length, 0.0), [150.0, -50.0], atol=1e-9)
    assert float(m.heading_at(m.length)) == pytest.approx(-math.pi / 2)
    # lane 1 (3.5 m left) is on the outside of a right turn: radius 50 + 3.5 around (100, -50)
    pts = m.lane(1).position(np.linspace(100.0, m.length, 7), 0.0)
    np.testing.assert_allclose(np.hypot(pts[:, 0] - 100.0, pts[:, 1] + 50.0), 53.5, atol=1e-9)


@pytest.mark.parametrize("index", [0, 1, -1])
def test_round_trip_position_local_coordinates(winding: RoadMap, index: int) -> None:
    lane = winding.lane(index)
    rng = np.random.default_rng(0)
    s = rng.uniform(-30.0, winding.length + 30.0, 2000)  # includes both extensions
    r = rng.uniform(-1.6, 1.6, 2000)
    s2, r2 = lane.local_coordinates(lane.position(s, r))
    np.testing.assert_allclose(s2, s, atol=1e-9, rtol=0)
    np.testing.assert_allclose(r2, r, atol=1e-9, rtol=0)


@pytest.mark.parametrize("angle_deg", [90.0, -90.0, 200.0, -270.0])
def test_round_trip_on_single_arcs_including_beyond_half_turn(angle_deg: float) -> None:
    m = make_map(seg(20.0), arc(40.0, angle_deg), seg(20.0))
    for index in (0, 1, -1):
        lane = m.lane(index)
        s = np.linspace(20.0, 20.0 + 40.0 * math.radians(abs(angle_deg)), 301)
        for r in (-1.7, 0.0, 1.2):
            s2, r2 = lane.local_coordinates(lane.position(s, r))
            np.testing.assert_allclose(s2, s, atol=1e-9, rtol=0)
            np.testing.assert_allclose(r2, r, atol=1e-9, rtol=0)


def test_joints_are_continuous_in_position_and_heading(winding: RoadMap) -> None:
    joints = np.array([p.s0 for p in winding.pieces[1:]])
    eps = 1e-7
    for d in (-4.0, 0.0, 5.0):
        before = winding.position(joints - eps, d)
        after = winding.position(joints, d)
        assert np.max(np.linalg.norm(after - before, axis=1)) < 1e-5
    dh = winding.heading_at(joints) - winding.heading_at(joints - eps)
    assert np.max(np.abs(dh)) < 1e-7
    # the pieces are laid end to end: each starts where the one before ends
    for p, q in zip(winding.pieces[:-1], winding.pieces[1:], strict=True):
        assert q.s0 == pytest.approx(p.s0 + p.length)
        assert q.heading0 == pytest.approx(p.heading0 + p.curvature * p.length)


def test_points_beyond_the_ends_project_onto_the_extensions() -> None:
    m = make_map(seg(100.0), arc(50.0, 90.0))
    s, r = m.lane(0).local_coordinates(np.array([[-10.0, 1.0], [151.0, 70.0]]))
    np.testing.assert_allclose(s, [-10.0, m.length + 20.0], atol=1e-9)
    np.testing.assert_allclose(r, [1.0, -1.0], atol=1e-9)


def test_lane_offsets_and_widths() -> None:
    m = make_map(seg(100.0, lanes=2, oncoming=2))
    s = np.array([10.0, 50.0])
    np.testing.assert_allclose(m.lane(1).offset_at(s), W)
    np.testing.assert_allclose(m.lane(-1).offset_at(s), 2 * W)  # (lanes - 0.5) w + 0.5 w
    np.testing.assert_allclose(m.lane(-2).offset_at(s), 3 * W)
    np.testing.assert_allclose(m.lane(0).width_at(s), W)
    assert [lane.direction for lane in (m.lane(0), m.lane(1), m.lane(-1), m.lane(-2))] == [
        1,
        1,
        -1,
        -1,
    ]
    assert m.lane(-2) is m.oncoming[1]
    with pytest.raises(IndexError):
        m.lane(2)
    with pytest.raises(IndexError):
        m.lane(-3)


def test_lane_existence_follows_per_segment_counts() -> None:
    m = make_map(seg(100.0, lanes=2, oncoming=0), seg(100.0, lanes=1, oncoming=2), seg(50.0))
    s = np.array([50.0, 99.999, 100.0, 150.0, 220.0])
    assert len(m.lanes) == 2 and len(m.oncoming) == 2
    assert m.lane(0).exists_at(s).tolist() == [True] * 5
    assert m.lane(1).exists_at(s).tolist() == [True, True, False, False, True]
    assert m.lane(-1).exists_at(s).tolist() == [False, False, True, True, True]
    assert m.lane(-2).exists_at(s).tolist() == [False, False, True, True, False]
    assert [m.lanes_at(x) for x in (0.0, 150.0, 249.0)] == [2, 1, 2]
    # the oncoming lane sits next to the centre line, which moves with the lane count
    np.testing.assert_allclose(m.lane(-1).offset_at([150.0, 220.0]), [W, 2 * W])
    c = m.cross_section_at(120.0)
    assert (c.lanes, c.oncoming_lanes, c.lane_width, c.shoulder) == (1, 2, W, SHOULDER)


def test_zone_carries_over_until_changed() -> None:
    m = make_map(seg(10.0), seg(10.0, zone=Zone.CITY), seg(10.0), seg(10.0, zone=Zone.RAMP))
    assert [m.cross_section_at(s).zone for s in (5, 15, 25, 35)] == [
        Zone.HIGHWAY,
        Zone.CITY,
        Zone.CITY,
        Zone.RAMP,
    ]


def test_paved_edges() -> None:
    m = make_map(seg(100.0, lanes=2, oncoming=1), seg(100.0, lanes=1, oncoming=0))
    right, left = m.paved_edges(np.array([50.0, 150.0]))
    np.testing.assert_allclose(right, -(0.5 * W + SHOULDER))
    np.testing.assert_allclose(left, [2.5 * W, 0.5 * W])


def test_speed_limit_postings() -> None:
    m = make_map(
        seg(100.0),
        seg(100.0, speed_kph=80.0),
        seg(100.0),
        speed_kph=50.0,
        features=(SpeedLimitSign(250.0, 30 * KPH), StopSign(120.0), SpeedLimitSign(40.0, 60 * KPH)),
    )
    assert [(p.s, round(p.limit / KPH)) for p in m.speed_limits] == [
        (0.0, 50),
        (40.0, 60),
        (100.0, 80),
        (250.0, 30),
    ]
    s = np.array([0.0, 39.9, 40.0, 99.0, 100.0, 249.0, 250.0, 299.0, 400.0])
    np.testing.assert_allclose(
        m.speed_limit_at(s) / KPH, [50, 50, 60, 60, 80, 80, 30, 30, 30], atol=1e-9
    )
    assert [f.s for f in m.features] == [40.0, 120.0, 250.0]


def test_a_posting_at_the_same_station_replaces_the_earlier() -> None:
    m = make_map(seg(100.0, speed_kph=70.0), seg(50.0), speed_kph=50.0)
    assert [(p.s, round(p.limit / KPH)) for p in m.speed_limits] == [(0.0, 70)]
    assert float(m.speed_limit_at(10.0)) == pytest.approx(70 * KPH)


def test_too_tight_arcs_raise_map_error() -> None:
    # left turn: the inner edge is the left paved edge at (2 + 1 - 0.5) * 3.5 = 8.75 m
    with pytest.raises(MapError, match="segments\\[1\\]"):
        make_map(seg(10.0), arc(8.75, 30.0))
    make_map(seg(10.0), arc(8.8, 30.0))
    # right turn: the inner edge is the shoulder's edge at 1.75 + 2.5 = 4.25 m
    with pytest.raises(MapError):
        make_map(arc(-4.2, -30.0))
    make_map(arc(-4.3, -30.0))


def test_arcs_beyond_a_full_turn_raise_map_error() -> None:
    make_map(arc(30.0, 360.0))
    with pytest.raises(MapError, match="360"):
        make_map(seg(10.0), arc(-30.0, -370.0))


def test_empty_road_raises_map_error() -> None:
    with pytest.raises(MapError):
        build_road_map(RoadSpec((), 10.0))


def test_curvature_of_lanes() -> None:
    m = make_map(seg(50.0), arc(50.0, 90.0), arc(-100.0, -30.0))
    np.testing.assert_allclose(m.curvature_at([10.0, 60.0, 140.0]), [0.0, 0.02, -0.01])
    np.testing.assert_allclose(m.lane(1).curvature_at(60.0), 1.0 / (50.0 - W))
    np.testing.assert_allclose(m.lane(-1).curvature_at(140.0), -1.0 / (100.0 + 2 * W))
    # the lane's curvature is its heading change per metre of its own length
    s = np.array([60.0, 61.0])
    p = m.lane(1).position(s, 0.0)
    ds_lane = float(np.linalg.norm(p[1] - p[0]))
    dh = float(np.diff(m.lane(1).heading_at(s))[0])
    assert dh / ds_lane == pytest.approx(float(m.lane(1).curvature_at(60.5)), rel=1e-4)


def test_lane_at(winding: RoadMap) -> None:
    # straight 1: lanes 0, 1, oncoming -1
    for index in (0, 1, -1):
        xy = winding.lane(index).position(50.0, 0.3)
        got, s, r = winding.lane_at(xy)
        assert got == index
        assert s == pytest.approx(50.0) and r == pytest.approx(0.3)
    # on the arc, near the lane 0 / lane 1 boundary, either side of it
    assert winding.lane_at(winding.lane(0).position(130.0, 0.5 * W - 0.01))[0] == 0
    assert winding.lane_at(winding.lane(0).position(130.0, 0.5 * W + 0.01))[0] == 1
    # third lane exists only on the 60 m straight; oncoming -2 there too
    s3 = 100.0 + 25.0 * math.pi + 30.0
    assert winding.lane_at(winding.lane(2).position(s3, 0.0))[0] == 2
    assert winding.lane_at(winding.lane(-2).position(s3, -1.0))[0] == -2
    # the shoulder, beyond the left edge and before the start are off every lane
    off = winding.lane_at(winding.lane(0).position(50.0, -0.5 * W - 1.0))
    assert off[0] is None and off[2] == pytest.approx(-0.5 * W - 1.0)
    assert winding.lane_at(winding.lane(-1).position(50.0, 1.8))[0] is None
    assert winding.lane_at((-5.0, 0.0))[0] is None


def test_vectorised_shapes() -> None:
    m = make_map(seg(100.0), arc(50.0, 90.0))
    lane = m.lane(1)
    assert lane.position(10.0, 0.0).shape == (2,)
    assert lane.position(np.arange(5.0), 0.0).shape == (5, 2)
    assert lane.position(10.0, np.zeros(3)).shape == (3, 2)
    assert lane.position([1.0, 2.0], [0.0, 0.5]).shape == (2, 2)
    s, r = lane.local_coordinates([10.0, 3.5])
    assert np.shape(s) == () and np.shape(r) == ()
    assert float(s) == pytest.approx(10.0) and float(r) == pytest.approx(0.0)
    s, r = lane.local_coordinates(np.zeros((7, 2)))
    assert s.shape == (7,) and r.shape == (7,)
    for f in (lane.offset_at, lane.heading_at, lane.width_at, lane.curvature_at, m.speed_limit_at):
        assert np.shape(f(3.0)) == ()
        assert np.shape(f(np.arange(4.0))) == (4,)
    assert lane.exists_at(np.arange(4.0)).dtype == np.bool_


def test_scalar_pose_and_curvature_equal_the_vectorised(winding: RoadMap) -> None:
    """`pose_one` / `curvature_one` (the NPCs' hot path) agree with `pose` / `curvature`
    everywhere, joints and the straight extensions beyond both ends included."""
    line = winding.line
    joints = np.array([p.s0 for p in winding.pieces] + [winding.length])
    s = np.concatenate([np.linspace(-30.0, winding.length + 30.0, 301), joints])
    d = np.linspace(-4.0, 6.0, len(s))
    x, y, h = line.pose(s, d)
    k = line.curvature(s)
    for i in range(len(s)):
        assert line.pose_one(float(s[i]), float(d[i])) == pytest.approx((x[i], y[i], h[i]),
                                                                        abs=1e-9)
        assert line.curvature_one(float(s[i])) == k[i]
    np.testing.assert_allclose(np.column_stack([x, y]), line.point(s, d), atol=1e-9)
    np.testing.assert_allclose(h, line.heading(s), atol=1e-12)


def crossing_loop() -> RoadMap:
    """East 100 m, three left quarter turns of 10 m (via north 50 m and west 30 m), then south
    100 m: the last straight crosses the first at (60, 0), 60 m and about 287 m along."""
    return make_map(seg(100.0), arc(10.0, 90.0), seg(50.0), arc(10.0, 90.0), seg(30.0),
                    arc(10.0, 90.0), seg(100.0))


def test_a_route_crossing_itself_keeps_the_pass_near_the_hint() -> None:
    road = crossing_loop()
    second = 100.0 + 50.0 + 30.0 + 3 * 5.0 * math.pi + 60.0  # the crossing, second time
    xy = np.array([[60.0, 0.3]])  # 0.3 m left of the first pass, on the second
    s, _ = road.local_coordinates(xy)  # the nearest of all: the second pass
    assert float(s[0]) == pytest.approx(second - 0.3, abs=1e-9)
    s, d = road.local_coordinates(xy, near=58.0)  # the car on the first pass
    assert float(s[0]) == pytest.approx(60.0, abs=1e-9) and float(d[0]) == pytest.approx(0.3)
    s, _ = road.local_coordinates(xy, near=second + 2.0)
    assert float(s[0]) == pytest.approx(second - 0.3, abs=1e-9)


def test_a_stale_hint_gives_way_to_the_nearest_pass() -> None:
    """A hint 60 m off (the car moved on while nobody looked): the pieces near it are tens
    of metres from the point, so the nearest of all is taken."""
    road = crossing_loop()
    s, d = road.local_coordinates(np.array([[20.0, 0.5]]), near=200.0)
    assert float(s[0]) == pytest.approx(20.0, abs=1e-9) and float(d[0]) == pytest.approx(0.5)
