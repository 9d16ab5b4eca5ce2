"""Speed targets: the table of constraints, and point-mass drives through limits and curves."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from planner.speed_planning import (
    Binding,
    SpeedPlanner,
    SpeedPlanningParams,
    SpeedTarget,
    _suffix_argmin,
    braking_speed,
    curve_speed,
)
from tests.planner.maps import KPH, real_map, road_spec, segment, straight_road
from tests.vehicle import VEHICLE
from world.hdmap import Crosswalk, RoadMap

P = SpeedPlanningParams()
A = P.a_comf
MARGIN = P.brake_margin
FRONT = VEHICLE.front_overhang
AXLE = VEHICLE.front_axle
R = 60.0  # [m]
V_R60 = math.sqrt(180.0)  # [m/s] sqrt(a_lat_max * R)
SIGN = 500.0  # [m] station of the lower posting
KINDS = ["double", "real"]


_PLANNERS: dict[tuple[int, int], SpeedPlanner] = {}


def target(
    road: RoadMap, s: float, set_kph: float, max_kph: float = 200.0, lane: int = 0
) -> SpeedTarget:
    """The target at ``s``, from one planner per (road, lane) (the map is sampled once)."""
    key = (id(road), lane)
    if key not in _PLANNERS or _PLANNERS[key].road is not road:
        _PLANNERS[key] = SpeedPlanner(road, road.lane(lane), P, VEHICLE)
    return _PLANNERS[key].target(s, set_speed=set_kph * KPH, max_speed=max_kph * KPH)


def limit_road(kind: str, before: float = 100.0, after: float = 50.0) -> RoadMap:
    return straight_road(kind, 1000.0, before, ((SIGN, after),))


# ---- straight roads and postings (run on the double and on the real map) ----------------


@pytest.mark.parametrize("kind", KINDS)
def test_straight_set_speed(kind: str) -> None:
    t = target(straight_road(kind, 1000.0, 100.0), 100.0, 80.0)
    assert t == SpeedTarget(80.0 * KPH, 0.0, 100.0 * KPH, Binding.SET_SPEED, 0.0)


@pytest.mark.parametrize("kind", KINDS)
def test_vehicle_max_speed(kind: str) -> None:
    t = target(straight_road(kind, 1000.0, 130.0), 100.0, 120.0, max_kph=110.0)
    assert t.speed == pytest.approx(110.0 * KPH)
    assert t.binding == Binding.MAX_SPEED


@pytest.mark.parametrize("kind", KINDS)
def test_posted_limit_with_margin(kind: str) -> None:
    t = target(straight_road(kind, 1000.0, 100.0), 100.0, 120.0)
    assert t.binding is Binding.LIMIT
    assert t.speed == pytest.approx((100.0 - 0.3) * KPH)
    assert t.limit_at_front == pytest.approx(100.0 * KPH)
    assert t.accel == 0.0


@pytest.mark.parametrize("kind", KINDS)
def test_lower_limit_100_m_ahead_gives_braking_curve(kind: str) -> None:
    t = target(limit_road(kind), SIGN - FRONT - 100.0, 120.0)
    v_c = (50.0 - 0.3) * KPH
    assert t.binding is Binding.LIMIT_AHEAD
    assert t.distance == pytest.approx(100.0)
    assert t.speed == pytest.approx(math.sqrt(v_c**2 + 2.0 * A * (100.0 - MARGIN)))
    assert t.speed < 100.0 * KPH
    assert t.accel == -A
    assert t.limit_at_front == pytest.approx(100.0 * KPH)


@pytest.mark.parametrize("kind", KINDS)
def test_far_from_lower_limit_the_current_limit_binds(kind: str) -> None:
    t = target(limit_road(kind), SIGN - FRONT - 250.0, 120.0)
    assert (t.binding, t.accel) == (Binding.LIMIT, 0.0)


@pytest.mark.parametrize("kind", KINDS)
def test_within_brake_margin_of_sign_target_is_the_limit(kind: str) -> None:
    t = target(limit_road(kind), SIGN - FRONT - 0.5 * MARGIN, 120.0)
    assert t.binding is Binding.LIMIT_AHEAD
    assert t.speed == pytest.approx((50.0 - 0.3) * KPH)
    assert t.accel == 0.0  # holding the limit, no more braking feed-forward


@pytest.mark.parametrize("kind", KINDS)
def test_front_bumper_exactly_at_sign(kind: str) -> None:
    t = target(limit_road(kind), SIGN - FRONT, 120.0)
    assert t.binding is Binding.LIMIT
    assert t.limit_at_front == pytest.approx(50.0 * KPH)
    assert t.speed <= 50.0 * KPH
    # the centre is still in the 100 zone: the limit counts from the front bumper
    t_before = target(limit_road(kind), SIGN - FRONT - 1e-3, 120.0)
    assert t_before.limit_at_front == pytest.approx(100.0 * KPH)
    assert t_before.speed <= 50.0 * KPH


@pytest.mark.parametrize("kind", KINDS)
def test_higher_limit_ahead_never_binds(kind: str) -> None:
    road = limit_road(kind, before=50.0, after=100.0)
    t = target(road, SIGN - FRONT - 10.0, 120.0)
    assert t.binding == Binding.LIMIT
    assert t.speed == pytest.approx((50.0 - 0.3) * KPH)
    t = target(road, SIGN - FRONT + 0.1, 120.0)
    assert t.binding == Binding.LIMIT
    assert t.speed == pytest.approx((100.0 - 0.3) * KPH)


@pytest.mark.parametrize("kind", KINDS)
def test_far_posting_binds_exactly_when_its_braking_curve_falls_below_max_speed(
    kind: str,
) -> None:
    """No horizon: a 10 km/h posting 2.2 km ahead is taken into account, and binds from the
    distance where braking at a_comf from max speed must begin (plus the brake margin)."""
    v_max, v_c = 100.0 * KPH, (10.0 - 0.3) * KPH
    start = (v_max**2 - v_c**2) / (2.0 * A) + MARGIN  # [m] bumper -> sign where it binds
    road = straight_road(kind, 3000.0, 130.0, ((2500.0, 10.0),))
    assert target(road, 2500.0 - FRONT - 2200.0, 120.0, 100.0).binding is Binding.MAX_SPEED
    assert target(road, 2500.0 - FRONT - (start + 1.0), 120.0, 100.0).binding \
        is Binding.MAX_SPEED
    t = target(road, 2500.0 - FRONT - (start - 1.0), 120.0, 100.0)
    assert t.binding is Binding.LIMIT_AHEAD
    assert t.distance == pytest.approx(start - 1.0)
    assert t.speed < v_max


# ---- curves (real map) -------------------------------------------------------------------


def curve_road() -> RoadMap:
    """200 m straight, a 150 m left arc of R = 60 m, a 200 m straight; 130 km/h."""
    return real_map(road_spec([segment(200.0), segment(150.0, R), segment(200.0)], 130.0))


def test_curvature_speed_on_r60() -> None:
    t = target(curve_road(), 275.0, 120.0)
    assert t.binding is Binding.CURVE
    assert t.speed == pytest.approx(V_R60)
    assert t.speed == pytest.approx(13.4, abs=0.05)
    assert t.accel == 0.0


@pytest.mark.parametrize(("left", "radius"), [(True, R - 3.5), (False, R + 3.5)])
def test_curvature_speed_of_the_offset_lane(left: bool, radius: float) -> None:
    road = real_map(road_spec([segment(100.0), segment(150.0, R, left), segment(100.0)], 130.0))
    t = target(road, 175.0, 120.0, lane=1)
    assert t.binding is Binding.CURVE
    assert t.speed == pytest.approx(math.sqrt(3.0 * radius))


def test_curve_ahead_gives_braking_curve() -> None:
    d = 100.0  # [m] front axle -> arc start
    t = target(curve_road(), 200.0 - AXLE - d, 120.0)
    assert t.binding is Binding.CURVE_AHEAD
    assert t.accel == -A
    # the first curvature sample lies up to one sample spacing beyond the arc's start
    assert d <= t.distance <= d + P.sample_spacing
    lo = math.sqrt(V_R60**2 + 2.0 * A * (d - MARGIN))
    hi = math.sqrt(V_R60**2 + 2.0 * A * (d + P.sample_spacing - MARGIN))
    assert lo - 1e-9 <= t.speed <= hi + 1e-9


def test_curve_within_brake_margin_and_curve_exit() -> None:
    road = curve_road()
    t = target(road, 200.0 - AXLE - 1.0, 120.0)
    assert t.binding == Binding.CURVE_AHEAD
    assert t.speed == pytest.approx(V_R60)
    assert t.accel == 0.0
    # the centre is still in the arc, the front axle already on the straight: still CURVE
    t = target(road, 350.0 - 0.5 * AXLE, 120.0)
    assert t.binding == Binding.CURVE
    assert t.speed == pytest.approx(V_R60)
    t = target(road, 350.0 + 0.1, 120.0)
    assert t.binding is Binding.SET_SPEED


def test_lower_limit_at_the_curve_ties_go_to_limit() -> None:
    """Set speed below everything: the set speed binds even in the curve."""
    t = target(curve_road(), 275.0, 40.0)
    assert t.binding == Binding.SET_SPEED
    assert t.speed == pytest.approx(40.0 * KPH)


# ---- pure helpers --------------------------------------------------------------------------


def test_braking_and_curve_speed_helpers() -> None:
    v = braking_speed(np.array([10.0, 10.0, 10.0]), np.array([0.0, MARGIN, MARGIN + 10.0]), P)
    np.testing.assert_allclose(v, [10.0, 10.0, math.sqrt(100.0 + 2.0 * A * 10.0)])
    c = curve_speed(np.array([0.0, 1.0 / 60.0, -1.0 / 60.0, 1e-9]), P)
    np.testing.assert_allclose(c[1:3], V_R60)
    assert math.isinf(c[0]) and math.isinf(c[3])


# ---- point-mass drives with a perfect speed follower -----------------------------------------

DT = 1.0 / 40.0  # [s] planner tick


def drive(
    road: RoadMap, s0: float, v0: float, set_kph: float, until: float
) -> tuple[np.ndarray, np.ndarray, list[SpeedTarget]]:
    """Stations [m] and speeds [m/s] per tick of a point mass whose speed is the target."""
    s, v = s0, v0
    ss, vs, targets = [s], [v], []
    while s < until:
        t = target(road, s, set_kph)
        v_next = t.speed
        s += 0.5 * (v + v_next) * DT
        v = v_next
        ss.append(s)
        vs.append(v)
        targets.append(t)
    return np.array(ss), np.array(vs), targets


@pytest.mark.parametrize("kind", KINDS)
def test_drive_through_50_to_30_posting(kind: str) -> None:
    sign = 300.0
    road = straight_road(kind, 600.0, 50.0, ((sign, 30.0),))
    s, v, targets = drive(road, 50.0, (50.0 - 0.3) * KPH, 60.0, until=450.0)
    past = s + FRONT >= sign
    assert past.any()
    assert float(v[past].max()) <= 30.0 * KPH
    decel = -np.diff(v) / DT
    assert float(decel.max()) <= A + 0.02
    assert float(decel.max()) >= A - 0.1  # it did brake along the comfortable curve
    assert any(t.accel == -A for t in targets)
    assert v[-1] == pytest.approx((30.0 - 0.3) * KPH)


def test_drive_into_r60_curve() -> None:
    road = curve_road()
    v0 = target(road, 0.0, 200.0).speed  # already on the braking curve of the arc
    s, v, _ = drive(road, 0.0, v0, 200.0, until=300.0)
    in_curve = (s + AXLE >= 200.0) & (s <= 350.0)
    assert in_curve.any()
    assert float(v[in_curve].max()) <= V_R60 + 1e-9
    assert float((-np.diff(v) / DT).max()) <= A + 0.02


# ---- the precomputed envelope against brute force ------------------------------------------


def test_suffix_argmin_takes_the_nearest_of_equal_minima() -> None:
    values = np.array([3.0, 1.0, 2.0, 1.0, np.inf, 5.0, np.inf])
    np.testing.assert_array_equal(_suffix_argmin(values), [1, 1, 3, 3, 5, 5, 6])


def test_planner_equals_brute_force_over_every_sample() -> None:
    """At many stations of a winding road with postings, the target equals the plain rule
    evaluated over every map sample and posting ahead (no suffix minimum, no shortcuts)."""
    road = real_map(road_spec(
        [segment(120.0), segment(80.0, 45.0), segment(60.0), segment(90.0, 120.0, False),
         segment(40.0, 30.0), segment(150.0)],
        90.0, ((150.0, 60.0), (330.0, 30.0), (420.0, 70.0)),
    ))
    seen = set()
    for lane_index in (0, 1):
        lane = road.lane(lane_index)
        planner = SpeedPlanner(road, lane, P, VEHICLE)
        samples = np.array(planner._stations)
        kappa = np.asarray(lane.curvature_at(samples))
        metric = 1.0 / (1.0 + kappa * np.asarray(lane.offset_at(samples)))
        dist = np.concatenate(([0.0], np.cumsum(metric[:-1] * np.diff(samples))))

        def lane_distance(x: float, metric=metric, dist=dist, samples=samples) -> float:
            i = max(int(np.searchsorted(samples, x, side="right")) - 1, 0)
            return float(dist[i] + metric[i] * (x - samples[i]))

        for s in np.linspace(0.0, road.length - 5.0, 157):
            got = planner.target(float(s), set_speed=120 * KPH, max_speed=130 * KPH)
            seen.add(got.binding)
            i = max(int(np.searchsorted(samples, s, side="right")) - 1, 0)
            s_axle = s + AXLE / metric[i]
            s_front = s + FRONT / metric[i]
            d = np.array([lane_distance(x) for x in samples]) - lane_distance(s_axle)
            v_c = curve_speed(kappa, P)
            now = (samples <= s_axle) & (np.arange(len(samples)) >= i)
            ahead = samples > s_axle
            best = min(120 * KPH, 130 * KPH,
                       float(road.speed_limit_at(s_front)) - P.limit_margin,
                       float(v_c[now].min()),
                       float(braking_speed(v_c[ahead], d[ahead], P).min(initial=np.inf)))
            for post in road.speed_limits:
                if s_front < post.s <= road.length:
                    dp = lane_distance(post.s) - lane_distance(s_front)
                    best = min(best, float(braking_speed(
                        np.array(post.limit - P.limit_margin), np.array(dp), P)))
            assert got.speed == pytest.approx(best, rel=1e-9, abs=1e-9), (lane_index, s)
    # every kind of map constraint was exercised
    assert {Binding.CURVE, Binding.CURVE_AHEAD, Binding.LIMIT, Binding.LIMIT_AHEAD} <= seen


# ---- marked crossings (issue K: a pedestrian tracked from ~20 m is stopped for within comfort)


def test_a_crossing_caps_the_speed_within_its_sight_and_brakes_towards_it() -> None:
    crossing = 400.0
    spec = road_spec([segment(1000.0)], 40.0)
    road = real_map(replace(spec, features=(*spec.features, Crosswalk(s=crossing, width=4.0))))
    far = target(road, 100.0, 40.0)  # 300 m before: the posted limit
    assert far.binding is Binding.LIMIT
    d_sight = crossing - P.crossing_sight  # the cap holds from here (front bumper)
    near = target(road, d_sight - FRONT + 5.0, 40.0)
    assert near.binding is Binding.CROSSING and near.speed == pytest.approx(P.crossing_speed)
    ahead = target(road, d_sight - FRONT - 10.0, 40.0)  # 10 m before the cap: its curve
    assert ahead.binding is Binding.CROSSING and ahead.accel == -A
    assert ahead.speed == pytest.approx(math.sqrt(P.crossing_speed**2 + 2 * A * (10 - MARGIN)),
                                        rel=1e-3)
    past = target(road, crossing - FRONT + 0.5, 40.0)  # the bumper on the crossing: free
    assert past.binding is Binding.LIMIT


def test_a_pedestrian_waiting_at_a_crossing_lowers_its_speed_and_curve() -> None:
    """With a pedestrian waiting at the crossing (`target`'s ``waiting``) its speed is
    ``crossing_speed_waiting`` within its sight and the braking curve leads to that; a
    crossing without one (another station) keeps ``crossing_speed``."""
    crossing = 400.0
    spec = road_spec([segment(1000.0)], 50.0)
    road = real_map(replace(spec, features=(*spec.features, Crosswalk(s=crossing, width=4.0))))
    planner = SpeedPlanner(road, road.lane(0), P, VEHICLE)
    d_sight = crossing - P.crossing_sight

    def at(s: float, waiting: tuple[float, ...]) -> SpeedTarget:
        return planner.target(s, set_speed=50 * KPH, max_speed=200 * KPH, waiting=waiting)

    assert P.crossing_speed_waiting < P.crossing_speed
    near = at(d_sight - FRONT + 5.0, (crossing,))
    assert near.binding is Binding.CROSSING
    assert near.speed == pytest.approx(P.crossing_speed_waiting)
    assert at(d_sight - FRONT + 5.0, (crossing + 50.0,)).speed == pytest.approx(
        P.crossing_speed)
    ahead = at(d_sight - FRONT - 10.0, (crossing,))
    assert ahead.binding is Binding.CROSSING and ahead.accel == -A
    assert ahead.speed == pytest.approx(
        math.sqrt(P.crossing_speed_waiting**2 + 2 * A * (10 - MARGIN)), rel=1e-3)
