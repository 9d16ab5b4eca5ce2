"""Stanley + PID (ICCAS Eq. 1): front-axle projection and the steering law, case by case."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from control.stanley import FrontAxleError, StanleyPid, front_axle_error
from planner.messages import ReferencePath
from tests.control.paths import straight, straight_then_arc
from tests.vehicle import stanley_params
from world.frames import wrap_angle

L = 2.7  # [m] wheelbase
DT = 0.05  # [s]


# --- wrap_angle ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("angle", "expected"),
    [
        (0.0, 0.0),
        (math.pi, math.pi),
        (-math.pi, math.pi),
        (3 * math.pi, math.pi),
        (2 * math.pi + 0.1, 0.1),
        (-math.pi - 0.1, math.pi - 0.1),
        (-0.5, -0.5),
    ],
)
def test_wrap_angle_to_half_open_interval(angle: float, expected: float) -> None:
    assert wrap_angle(angle) == pytest.approx(expected)


# --- front_axle_error --------------------------------------------------------------------------


@pytest.mark.parametrize(("y", "expected_e"), [(1.0, -1.0), (-0.5, 0.5), (0.0, 0.0)])
def test_straight_sign_right_of_path_is_positive(y: float, expected_e: float) -> None:
    err = front_axle_error(straight(20.0), 0.0, y, 0.0, L)
    assert err.e_fa == pytest.approx(expected_e)
    assert err.theta_p == pytest.approx(0.0)
    assert err.curvature == 0.0
    # front axle at x = 1.35: on the segment 1.0 -> 1.5 of the 0.5 m spaced path
    assert err.index == 2


def test_projects_the_front_axle_not_the_centre() -> None:
    # car centre on the x-axis path but pointing left (+y): its front axle is L/2 left of it
    err = front_axle_error(straight(20.0), 5.0, 0.0, math.pi / 2, L)
    assert err.e_fa == pytest.approx(-L / 2)
    moved = front_axle_error(straight(20.0), 5.0, 0.0, math.pi / 2, L, centre_to_front_axle=2.0)
    assert moved.e_fa == pytest.approx(-2.0)


def test_diagonal_path_and_heading() -> None:
    path = straight(30.0, heading=math.pi / 4)
    # centre 1 m to the right of the diagonal (normal to the right is (+1, -1)/sqrt 2)
    x, y = 10.0 + 1.0 / math.sqrt(2), 10.0 - 1.0 / math.sqrt(2)
    err = front_axle_error(path, x, y, math.pi / 4, L)
    assert err.e_fa == pytest.approx(1.0)
    assert err.theta_p == pytest.approx(math.pi / 4)


@pytest.mark.parametrize("left", [True, False])
@pytest.mark.parametrize(("radial_offset", "outside_is_right"), [(0.3, True), (-0.3, False)])
def test_circle_value_sign_heading_curvature(
    left: bool, radial_offset: float, outside_is_right: bool
) -> None:
    radius = 60.0
    path = straight_then_arc(0.0, radius, math.pi, left=left)
    sign = 1.0 if left else -1.0
    a = 0.7  # [rad] angle along the arc of the front axle's foot point
    r = radius + radial_offset
    front = np.array([r * math.sin(a), sign * (radius - r * math.cos(a))])
    heading = sign * a + 0.05
    centre = front - L / 2 * np.array([math.cos(heading), math.sin(heading)])
    err = front_axle_error(path, float(centre[0]), float(centre[1]), heading, L)
    # outside of a left turn is its right side; of a right turn, its left side
    right = outside_is_right == left
    expected = abs(radial_offset) if right else -abs(radial_offset)
    chord_sag = 0.5**2 / (8 * radius)  # [m] polyline vs circle
    assert err.e_fa == pytest.approx(expected, abs=chord_sag + 1e-9)
    assert err.theta_p == pytest.approx(sign * a, abs=1e-3)
    assert err.curvature == pytest.approx(sign / radius)


def test_heading_and_curvature_interpolate_across_the_wrap() -> None:
    xy = np.array([[0.0, 0.0], [-1.0, 0.0], [-2.0, 0.0]])
    path = ReferencePath(
        xy=xy,
        heading=np.array([math.pi - 0.1, -math.pi + 0.1, -math.pi + 0.1]),
        curvature=np.array([0.0, 0.02, 0.02]),
    )
    # front axle at x = -0.5, the middle of segment 0 (car heading -x, centre at x = 0.85)
    err = front_axle_error(path, -0.5 + L / 2, 0.0, math.pi, L)
    assert err.index == 0
    assert err.theta_p == pytest.approx(math.pi)
    assert err.curvature == pytest.approx(0.01)


def test_beyond_the_ends_the_error_stays_lateral() -> None:
    path = straight(10.0)
    ahead = front_axle_error(path, 20.0, 0.4, 0.0, L)  # 11 m past the end, 0.4 m left
    behind = front_axle_error(path, -8.0, -0.4, 0.0, L)  # before the start, 0.4 m right
    assert ahead.e_fa == pytest.approx(-0.4)
    assert ahead.index == len(path.xy) - 2
    assert behind.e_fa == pytest.approx(0.4)
    assert behind.index == 0


def test_hint_keeps_the_match_on_the_right_lap() -> None:
    # two laps of a circle: the same place appears twice in the path
    path = straight_then_arc(0.0, 20.0, 4 * math.pi)
    per_lap = round(2 * math.pi * 20.0 / 0.5)
    x, y, heading = 5.0, 0.5, 0.25  # front axle about 6.3 m along the first lap
    first = front_axle_error(path, x, y, heading, L, hint_index=10)
    second = front_axle_error(path, x, y, heading, L, hint_index=10 + per_lap)
    assert 10 <= first.index < 20
    assert 10 + per_lap - 1 <= second.index < 20 + per_lap
    assert second.e_fa == pytest.approx(first.e_fa, abs=0.5**2 / (8 * 20.0))


@pytest.mark.parametrize("hint", [10_000, -5, 0, 500])
def test_stale_or_out_of_range_hint_falls_back_to_a_full_search(hint: int) -> None:
    path = straight(400.0)
    err = front_axle_error(path, 150.2 - L / 2, 0.3, 0.0, L, hint_index=hint)
    assert err.index == 300
    assert err.e_fa == pytest.approx(-0.3)


def test_degenerate_path_is_rejected() -> None:
    one = ReferencePath(xy=np.zeros((1, 2)), heading=np.zeros(1), curvature=np.zeros(1))
    with pytest.raises(ValueError, match="two points"):
        front_axle_error(one, 0.0, 0.0, 0.0, L)


def test_duplicate_points_do_not_break_the_projection() -> None:
    xy = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]])
    path = ReferencePath(xy=xy, heading=np.zeros(5), curvature=np.zeros(5))
    err = front_axle_error(path, 1.0 - L / 2, -0.2, 0.0, L)
    assert err.e_fa == pytest.approx(0.2)


# --- StanleyPid ---------------------------------------------------------------------------------

WIDE = stanley_params(ki=0.0, k_yaw=0.0, max_steer=math.pi / 2, max_steer_rate=1e6)


def error(e_fa: float = 0.0, theta_p: float = 0.0, curvature: float = 0.0) -> FrontAxleError:
    return FrontAxleError(index=0, e_fa=e_fa, theta_p=theta_p, curvature=curvature)


@pytest.mark.parametrize(
    ("case", "e_fa", "theta_p", "heading", "speed", "expected"),
    [
        ("on the path", 0.0, 0.0, 0.0, 10.0, 0.0),
        ("left of path steers right", -1.0, 0.0, 0.0, 10.0, math.atan(-2.5 / 11.0)),
        ("right of path steers left", 1.0, 0.0, 0.0, 10.0, math.atan(2.5 / 11.0)),
        ("heading error only", 0.0, 0.1, 0.0, 10.0, 0.1),
        ("heading error wraps", 0.0, math.pi - 0.05, -math.pi + 0.05, 10.0, -0.1),
        ("both add", 0.5, 0.1, 0.0, 5.0, 0.1 + math.atan(1.25 / 6.0)),
        ("reversing speed counts as 0", 1.0, 0.0, 0.0, -2.0, math.atan(2.5 / 1.0)),
    ],
)
def test_stanley_law_table(
    case: str, e_fa: float, theta_p: float, heading: float, speed: float, expected: float
) -> None:
    steer = StanleyPid(WIDE).update(error(e_fa, theta_p), heading, speed, 0.0, DT)
    assert steer == pytest.approx(expected), case


def test_left_of_path_gives_negative_steer_with_defaults() -> None:
    assert StanleyPid(stanley_params()).update(error(e_fa=-1.0), 0.0, 10.0, 0.0, DT) < 0.0


def test_softening_keeps_low_speed_steer_below_the_plain_law() -> None:
    plain = math.atan(2.5 * 1.0 / 0.1)  # the law without k_soft: ~88 deg
    soft = StanleyPid(WIDE).update(error(e_fa=1.0), 0.0, 0.1, 0.0, DT)
    assert soft == pytest.approx(math.atan(2.5 / 1.1))
    assert soft < plain - 0.3
    limited = StanleyPid(stanley_params())
    for _ in range(100):
        steer = limited.update(error(e_fa=1.0), 0.0, 0.1, 0.0, DT)
        assert abs(steer) <= limited.params.max_steer + 1e-12


def test_angle_and_rate_limits_are_honoured() -> None:
    ctrl = StanleyPid(stanley_params())
    p = ctrl.params
    previous = 0.0
    sequence = [error(e_fa=5.0)] * 40 + [error(e_fa=-5.0)] * 60 + [error()] * 40
    for err in sequence:
        steer = ctrl.update(err, 0.0, 3.0, 0.0, DT)
        assert abs(steer) <= p.max_steer + 1e-12
        assert abs(steer - previous) <= p.max_steer_rate * DT + 1e-12
        previous = steer
    first = StanleyPid(stanley_params()).update(error(e_fa=5.0), 0.0, 3.0, 0.0, DT)
    assert first == pytest.approx(p.max_steer_rate * DT)


def test_saturates_at_the_angle_limit() -> None:
    ctrl = StanleyPid(stanley_params())
    for _ in range(100):
        steer = ctrl.update(error(e_fa=-5.0), 0.0, 3.0, 0.0, DT)
    assert steer == pytest.approx(-ctrl.params.max_steer)


def test_reset_starts_the_rate_limit_from_the_given_angle() -> None:
    ctrl = StanleyPid(stanley_params())
    ctrl.reset(steering_angle=0.3)
    steer = ctrl.update(error(), 0.0, 10.0, 0.0, DT)
    assert steer == pytest.approx(0.3 - ctrl.params.max_steer_rate * DT)


def test_curvature_feed_forward_and_yaw_damping_terms() -> None:
    kappa = 1.0 / 60.0
    ff = StanleyPid(replace(WIDE, k_ff=1.0)).update(error(curvature=kappa), 0.0, 10.0, 0.0, DT)
    assert ff == pytest.approx(math.atan(L * kappa))
    # yaw rate above the path's (v kappa = 0) steers against it
    damped = StanleyPid(replace(WIDE, k_yaw=0.1)).update(error(), 0.0, 10.0, 0.2, DT)
    assert damped == pytest.approx(-0.02)
    # yaw rate equal to the path's: no damping
    matched = StanleyPid(replace(WIDE, k_yaw=0.1)).update(
        error(curvature=kappa), 0.0, 12.0, 0.2, DT
    )
    assert matched == pytest.approx(0.0)


def test_integral_acts_and_is_clamped() -> None:
    ctrl = StanleyPid(replace(WIDE, ki=1.0, integral_limit=0.5))
    for _ in range(200):
        ctrl.update(error(e_fa=0.2), 0.0, 10.0, 0.0, DT)
    assert ctrl.integral_term == pytest.approx(0.5)
    steer = ctrl.update(error(e_fa=0.0), 0.0, 10.0, 0.0, DT)
    assert steer == pytest.approx(math.atan(0.5 / 11.0))


def test_integrator_frozen_at_low_speed() -> None:
    ctrl = StanleyPid(replace(stanley_params(), ki=1.0))
    for _ in range(100):
        ctrl.update(error(e_fa=1.0), 0.0, 0.5, 0.0, DT)
    assert ctrl.integral_term == 0.0


def test_integrator_frozen_while_saturated() -> None:
    ctrl = StanleyPid(replace(stanley_params(), ki=1.0, integral_limit=10.0))
    for _ in range(200):
        steer = ctrl.update(error(e_fa=3.0), 0.0, 5.0, 0.0, DT)
    assert steer == pytest.approx(ctrl.params.max_steer)
    # only the steps before the command hit the limit integrated
    assert ctrl.integral_term < 3.0 * DT * 2
