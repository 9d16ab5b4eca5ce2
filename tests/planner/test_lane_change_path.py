"""Lane-change path: Hermite end conditions, duration vs lateral acceleration, map paths."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planner.lane_change_path import (
    LaneChangeParams,
    LaneChangePath,
    can_start,
    heading_error,
    path_length,
    peak_lateral_accel,
    plan_duration,
    route_pose,
    start_lane_change,
    start_lane_change_at,
)
from tests.roads import W, arc, make_map, seg

P = LaneChangeParams()
V = 13.9  # [m/s] 50 km/h


def wrap(a: np.ndarray) -> np.ndarray:
    return np.mod(a + math.pi, 2.0 * math.pi) - math.pi


def numeric_peak(path: LaneChangePath, speed: float) -> float:
    """v^2 max |r''| from a second difference of sampled offsets (no closed form)."""
    h = 0.01
    s = np.arange(path.s0 + h, path.end - h / 2, h)
    r = path.offset_at(s)
    return speed * speed * float(np.max(np.abs(np.diff(r, 2)))) / (h * h)


def planned(dr: float, psi: float, speed: float) -> LaneChangePath:
    m0 = math.tan(psi)
    t = plan_duration(dr, m0, speed, P)
    return LaneChangePath(10.0, path_length(speed, t, P), -dr, m0, t, 1)


@pytest.mark.parametrize(("r0", "m0"), [(-3.5, 0.0), (3.5, 0.05), (-3.2, -0.04), (0.3, 0.1)])
def test_hermite_end_conditions(r0: float, m0: float) -> None:
    path = LaneChangePath(20.0, 60.0, r0, m0, 4.0, 1)
    assert path.offset_at(20.0) == pytest.approx(r0, abs=1e-12)
    assert path.slope_at(20.0) == pytest.approx(m0, abs=1e-12)
    assert path.offset_at(80.0) == pytest.approx(0.0, abs=1e-12)
    assert path.slope_at(80.0) == pytest.approx(0.0, abs=1e-12)
    # derivatives agree with central differences, inside and outside the cubic
    s = np.linspace(5.0, 95.0, 181)
    h = 1e-4
    np.testing.assert_allclose(
        path.slope_at(s), (path.offset_at(s + h) - path.offset_at(s - h)) / (2 * h), atol=1e-6)
    inner = s[(s > 20.5) & (s < 79.5)]
    dd = (path.offset_at(inner + h) - 2 * path.offset_at(inner) + path.offset_at(inner - h)) / h**2
    np.testing.assert_allclose(path.second_derivative_at(inner), dd, atol=1e-4)
    # before: straight extension of the start; after: the target lane's centre
    np.testing.assert_allclose(path.offset_at([0.0, 10.0]), [r0 - 20 * m0, r0 - 10 * m0])
    np.testing.assert_allclose(path.offset_at([90.0, 200.0]), 0.0)
    np.testing.assert_allclose(path.second_derivative_at([10.0, 90.0]), 0.0)


def test_parallel_3p5m_change_at_50kph() -> None:
    path = planned(W, 0.0, V)
    assert 4.55 <= path.duration <= 5.0
    assert path.duration == pytest.approx(5.0)  # sqrt(6 * 3.5 / 0.85) = 4.97 s, next grid step
    assert path.length == pytest.approx(V * path.duration)
    peak = numeric_peak(path, V)
    assert peak <= P.a_lat_design + 1e-3
    assert peak == pytest.approx(6 * W / 25.0, rel=1e-3)  # 0.84 m/s^2: not over-conservative
    assert path.peak_lateral_accel(V) == pytest.approx(peak, rel=1e-3)


@pytest.mark.parametrize(
    ("dr", "psi", "speed"),
    [(W, 0.0, V), (-W, 0.0, V), (W, 0.03, V), (W, -0.03, V), (-W, 0.08, 10.0), (W, 0.15, V),
     (1.0, 0.0, 15.0), (W, 0.0, 25.0)],
)
def test_duration_is_smallest_grid_step_within_design(dr: float, psi: float, speed: float) -> None:
    path = planned(dr, psi, speed)
    k = (path.duration - P.t_min) / 0.05
    assert k == pytest.approx(round(k), abs=1e-6)
    assert P.t_min <= path.duration <= P.t_cap
    assert numeric_peak(path, speed) <= P.a_lat_design + 1e-3
    if path.duration > P.t_min:
        shorter = path_length(speed, path.duration - 0.05, P)
        assert peak_lateral_accel(dr, path.m0, speed, shorter) > P.a_lat_design
        faster = LaneChangePath(10.0, shorter, -dr, path.m0, path.duration - 0.05, 1)
        assert numeric_peak(faster, speed) > P.a_lat_design - 1e-3


def test_heading_error_changes_duration_as_closed_form() -> None:
    # toward the target: a(T) = max(|21 - 4 v T m|, |21 - 2 v T m|) / T^2 with m = tan(0.03),
    # first <= 0.85 at T = 4.55 (4.50 gives 0.852)
    assert planned(W, 0.03, V).duration == pytest.approx(4.55)
    # away from it: (21 + 4 v T tan 0.03) / T^2 <= 0.85 from T = 6.05: beyond t_max
    away = planned(W, -0.03, V)
    assert away.duration == pytest.approx(6.05)
    assert away.peak_lateral_accel(V) <= P.a_lat_design
    # far away: not even t_cap meets it; the cap holds and the peak is over the design value
    capped = planned(W, -0.1, V)
    assert capped.duration == pytest.approx(P.t_cap)
    assert capped.peak_lateral_accel(V) > P.a_lat_design


def test_low_speed_uses_min_length() -> None:
    path = planned(W, 0.0, 2.0)
    assert path.duration == pytest.approx(P.t_min)
    assert path.length == pytest.approx(P.min_length)
    assert numeric_peak(path, 2.0) <= P.a_lat_design
    standstill = planned(W, 0.0, 0.0)
    assert standstill.length == pytest.approx(P.min_length)


@pytest.mark.parametrize(
    ("source", "target", "y", "heading"),
    [(0, 1, 0.2, 0.02), (1, 0, W - 0.1, -0.01), (0, 1, -0.1, 2 * math.pi + 0.01)],
)
def test_reference_path_on_straight_map(source: int, target: int, y: float, heading: float) -> None:
    road = make_map(seg(300.0))
    assert road.lane_at((50.0, y))[0] == source
    lane = road.lane(target)
    change = start_lane_change(lane, target, 50.0, y, heading, V, P)
    assert change.s0 == pytest.approx(50.0)
    assert change.r0 == pytest.approx(y - target * W)
    assert change.m0 == pytest.approx(math.tan(wrap(np.array(heading))))
    path = change.reference_path(lane, 50.0, 0.0, 100.0, 0.5, road.length)
    np.testing.assert_allclose(path.xy[0], [50.0, y], atol=0.01)
    assert path.heading[0] == pytest.approx(wrap(np.array(heading)), abs=1e-12)
    s, r = lane.local_coordinates(path.xy)
    np.testing.assert_allclose(r[s >= change.end], 0.0, atol=1e-9)
    np.testing.assert_allclose(path.xy[-1], [150.0, target * W], atol=1e-9)
    # headings: the chords' direction; curvature: d heading / d arc length
    chord = np.diff(path.xy, axis=0)
    gaps = np.linalg.norm(chord, axis=1)
    mid = 0.5 * (path.heading[1:] + path.heading[:-1])
    chord_error = wrap(np.arctan2(chord[:, 1], chord[:, 0]) - mid)
    np.testing.assert_allclose(chord_error, 0.0, atol=5e-4)  # ~ k h / 8 over the curvature steps
    smooth = (s[1:] > change.s0 + 0.5) & (s[:-1] < change.end - 0.5)  # curvature steps at ends
    dh_ds = np.diff(path.heading) / gaps
    mid_k = 0.5 * (path.curvature[1:] + path.curvature[:-1])
    np.testing.assert_allclose(chord_error[smooth], 0.0, atol=1e-5)
    np.testing.assert_allclose(dh_ds[smooth], mid_k[smooth], atol=1e-5)
    assert np.max(np.abs(path.curvature)) * V * V <= P.a_lat_design
    # the start is behind the car: its straight extension, on the car's heading
    back = change.reference_path(lane, 50.0, 10.0, 20.0, 0.5, road.length)
    np.testing.assert_allclose(wrap(back.heading[:20] - heading), 0.0, atol=1e-12)
    np.testing.assert_allclose(back.xy[20], [50.0, y], atol=1e-9)


@pytest.mark.parametrize(
    ("source", "target", "angle", "duration"), [(0, 1, 90.0, 4.9), (1, 0, -60.0, 5.05)])
def test_reference_path_on_arc(source: int, target: int, angle: float, duration: float) -> None:
    road = make_map(seg(50.0), arc(120.0, angle), seg(150.0))
    s_car = 80.0
    car = road.lane(source).position(s_car, 0.1)
    heading = float(road.lane(source).heading_at(s_car))
    lane = road.lane(target)
    change = start_lane_change(lane, target, float(car[0]), float(car[1]), heading, V, P)
    assert change.s0 == pytest.approx(s_car, abs=1e-9)
    assert change.r0 == pytest.approx(0.1 + (source - target) * W, abs=1e-9)
    assert change.duration == pytest.approx(duration)  # sqrt(6 |r0| / 0.85), 3.4 / 3.6 m
    path = change.reference_path(lane, s_car, 0.0, 120.0, 0.5, road.length)
    np.testing.assert_allclose(path.xy[0], car, atol=0.01)
    s, r = lane.local_coordinates(path.xy)
    assert s[-1] > change.end
    np.testing.assert_allclose(r[s >= change.end], 0.0, atol=1e-9)
    np.testing.assert_allclose(r, change.offset_at(s), atol=1e-9)
    chord = np.diff(path.xy, axis=0)
    mid = 0.5 * (path.heading[1:] + path.heading[:-1])
    np.testing.assert_allclose(wrap(np.arctan2(chord[:, 1], chord[:, 0]) - mid), 0.0, atol=5e-3)


def test_progress_done_and_checks() -> None:
    path = LaneChangePath(20.0, 60.0, -W, 0.0, 4.3, 1)
    assert [path.progress(s) for s in (0.0, 20.0, 50.0, 80.0, 99.0)] == [0.0, 0.0, 0.5, 1.0, 1.0]
    assert not path.done(79.9) and path.done(80.0)
    assert path.done(85.0, 0.2) and not path.done(85.0, 0.8) and not path.done(70.0, 0.0)
    road = make_map(seg(100.0))
    with pytest.raises(ValueError, match="target lane"):
        start_lane_change(road.lane(0), 1, 10.0, 0.0, 0.0, V, P)
    with pytest.raises(ValueError, match="target lane"):
        path.reference_path(road.lane(0), 20.0, 0.0, 30.0, 0.5, road.length)
    with pytest.raises(ValueError, match="heading error"):
        start_lane_change(road.lane(1), 1, 10.0, 0.0, 2.0, V, P)


def test_a_bend_that_turns_back_plans_from_the_cars_own_pass() -> None:
    """A 200 deg bend (radius 8 m) brings the route back across its entry: the car's point
    at station 10 m is also the nearest point of the exit, where the lane heads ~160 deg the
    other way. With the car's station as the hint the path starts at the car's own pass."""
    road = make_map(seg(60.0, lanes=2, oncoming=0), arc(-8.0, -200.0, lanes=2, oncoming=0),
                    seg(60.0, lanes=2, oncoming=0))
    x, y, heading = 10.0, 1.0, float(road.lane(0).heading_at(10.0))
    with pytest.raises(ValueError, match=r"heading error -2\.79"):
        start_lane_change(road.lane(1), 1, x, y, heading, V, P)  # no hint: the exit
    assert not can_start(road.lane(1), x, y, heading)
    assert can_start(road.lane(1), x, y, heading, near=10.0)
    change = start_lane_change(road.lane(1), 1, x, y, heading, V, P, near=10.0)
    assert change.s0 == pytest.approx(10.0) and change.m0 == pytest.approx(0.0, abs=1e-9)
    assert change.r0 == pytest.approx(1.0 - W)


ROADS = {
    "straight": make_map(seg(120.0, lanes=3, oncoming=1)),
    "bends": make_map(seg(40.0, lanes=2, oncoming=1), arc(60.0, 50.0, lanes=2, oncoming=1),
                      arc(-45.0, -70.0, lanes=2, oncoming=1), seg(40.0, lanes=2, oncoming=1)),
    "turning back": make_map(seg(60.0, lanes=2, oncoming=0),
                             arc(-8.0, -200.0, lanes=2, oncoming=0),
                             seg(60.0, lanes=2, oncoming=0)),
}


@pytest.mark.parametrize("name", list(ROADS))
def test_route_pose_answers_as_each_lanes_own_projection(name: str) -> None:
    """One `RoutePose` per car pose and hint gives, for every lane, the very bits of
    `heading_error` (its own projection onto that lane), and `can_start` for each."""
    road = ROADS[name]
    lanes = [road.lane(k) for k in range(len(road.lanes))] + list(road.oncoming)
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(60):
        s = float(rng.uniform(-5.0, road.length + 5.0))
        x, y = (float(v) for v in road.position(s, float(rng.uniform(-4.0, 8.0))))
        heading = float(rng.uniform(-math.pi, math.pi))
        for near in (None, s, float(rng.uniform(0.0, road.length))):
            pose = route_pose(road, x, y, heading, near)
            assert pose.is_for(x, y, heading, near)
            for lane in lanes:
                own = heading_error(lane, x, y, heading, near)
                assert pose.in_lane(lane) == own  # bit for bit
                assert pose.can_start is can_start(lane, x, y, heading, near)
                checked += 1
    assert checked == 60 * 3 * len(lanes)


def test_a_path_from_the_route_pose_is_the_path_from_the_lane() -> None:
    road = ROADS["bends"]
    for s in (10.0, 70.0, 120.0):
        x, y = (float(v) for v in road.position(s, 0.4))
        heading = float(road.heading_at(s)) + 0.05
        pose = route_pose(road, x, y, heading, s)
        for k in (1, -1):
            lane = road.lane(k)
            assert start_lane_change_at(lane, k, pose, V, P) == \
                start_lane_change(lane, k, x, y, heading, V, P, near=s)
    with pytest.raises(ValueError, match="not the target lane"):
        start_lane_change_at(road.lane(0), 1, route_pose(road, 0.0, 0.0, 0.0), V, P)
