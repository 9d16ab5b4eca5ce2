"""Speed targets: the table of constraints, and point-mass drives through limits and curves."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planner.speed_planning import (
    Binding,
    SpeedPlanningParams,
    SpeedTarget,
    braking_speed,
    curve_speed,
    horizon,
    speed_target,
)
from tests.planner.maps import KPH, needs_hdmap, real_map, road_spec, segment, straight_road
from world.hdmap import RoadMap

P = SpeedPlanningParams()
A = P.a_comf
MARGIN = P.brake_margin
FRONT = P.front_overhang
AXLE = P.front_axle
R = 60.0  # [m]
V_R60 = math.sqrt(180.0)  # [m/s] sqrt(a_lat_max * R)
SIGN = 500.0  # [m] station of the lower posting
KINDS = ["double", "real"]


def target(
    road: RoadMap, s: float, set_kph: float, max_kph: float = 200.0, lane: int = 0
) -> SpeedTarget:
    return speed_target(
        road, road.lane(lane), s, set_speed=set_kph * KPH, max_speed=max_kph * KPH, params=P
    )


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
def test_posting_near_the_horizon(kind: str) -> None:
    """The horizon is the stopping distance from max speed plus 20 m: a 10 km/h posting
    there is still seen (braking curve just above max speed), none beyond it can bind."""
    h = horizon(100.0 * KPH, P)
    assert h == pytest.approx((100.0 * KPH) ** 2 / 3.0 + 20.0)
    road = straight_road(kind, 3000.0, 130.0, ((2500.0, 10.0),))
    t = target(road, 2500.0 - FRONT - (h - 10.0), 120.0, 100.0)
    assert t.binding is Binding.MAX_SPEED
    t = target(road, 2500.0 - FRONT - (h - 30.0), 120.0, 100.0)
    assert t.binding is Binding.LIMIT_AHEAD


# ---- curves (real map) -------------------------------------------------------------------


def curve_road() -> RoadMap:
    """200 m straight, a 150 m left arc of R = 60 m, a 200 m straight; 130 km/h."""
    return real_map(road_spec([segment(200.0), segment(150.0, R), segment(200.0)], 130.0))


@needs_hdmap
def test_curvature_speed_on_r60() -> None:
    t = target(curve_road(), 275.0, 120.0)
    assert t.binding is Binding.CURVE
    assert t.speed == pytest.approx(V_R60)
    assert t.speed == pytest.approx(13.4, abs=0.05)
    assert t.accel == 0.0


@needs_hdmap
@pytest.mark.parametrize(("left", "radius"), [(True, R - 3.5), (False, R + 3.5)])
def test_curvature_speed_of_the_offset_lane(left: bool, radius: float) -> None:
    road = real_map(road_spec([segment(100.0), segment(150.0, R, left), segment(100.0)], 130.0))
    t = target(road, 175.0, 120.0, lane=1)
    assert t.binding is Binding.CURVE
    assert t.speed == pytest.approx(math.sqrt(3.0 * radius))


@needs_hdmap
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


@needs_hdmap
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


@needs_hdmap
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


@needs_hdmap
def test_drive_into_r60_curve() -> None:
    road = curve_road()
    v0 = target(road, 0.0, 200.0).speed  # already on the braking curve of the arc
    s, v, _ = drive(road, 0.0, v0, 200.0, until=300.0)
    in_curve = (s + AXLE >= 200.0) & (s <= 350.0)
    assert in_curve.any()
    assert float(v[in_curve].max()) <= V_R60 + 1e-9
    assert float((-np.diff(v) / DT).max()) <= A + 0.02
