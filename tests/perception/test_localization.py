"""Localization EKF on a synthetic drive: straight, then a full circle, at 12 m/s."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from perception.localization import (
    Localizer,
    LocalizerParams,
    NotInitialisedError,
    motion,
    wheel_speed,
)
from world.frames import GnssFix, Odometry, wrap_angle

DEG = math.pi / 180.0
ODO_RATE = 40.0  # [Hz]
GNSS_EVERY = 4  # odometry samples per GNSS fix (10 Hz)
WHEEL_RADIUS = 0.33  # [m]
SPEED = 12.0  # [m/s]
RADIUS = 40.0  # [m]
T_STRAIGHT = 8.0  # [s]
HEADING0 = 2.8  # [rad] close to pi, so the circle crosses the +-pi wrap
SETTLE = 1.0  # [s] ignored at the start of the error statistics


@dataclass(frozen=True)
class Truth:
    x: float
    y: float
    heading: float
    speed: float
    yaw_rate: float


def truth_at(t: float) -> Truth:
    """Straight along HEADING0 for T_STRAIGHT, then a left circle of RADIUS, from (10, -5)."""
    x0, y0 = 10.0, -5.0
    if t <= T_STRAIGHT:
        d = SPEED * t
        return Truth(x0 + d * math.cos(HEADING0), y0 + d * math.sin(HEADING0), HEADING0, SPEED, 0.0)
    w = SPEED / RADIUS
    x1 = x0 + SPEED * T_STRAIGHT * math.cos(HEADING0)
    y1 = y0 + SPEED * T_STRAIGHT * math.sin(HEADING0)
    psi = HEADING0 + w * (t - T_STRAIGHT)
    x = x1 + RADIUS * (math.sin(psi) - math.sin(HEADING0))
    y = y1 + RADIUS * (-math.cos(psi) + math.cos(HEADING0))
    return Truth(x, y, wrap_angle(psi), SPEED, w)


def run(
    seed: int,
    duration: float,
    bias: tuple[float, float] = (0.0, 0.0),
    gnss_sigma: float = 0.05,
    heading_sigma: float = 0.2 * DEG,
) -> tuple[np.ndarray, np.ndarray]:
    """Position and heading errors [m], [rad] of the estimate after each tick past SETTLE.

    Errors are against the truth shifted by the GNSS bias (what the filter can observe).
    """
    rng = np.random.default_rng(seed)
    loc = Localizer()
    spin_sigma = 0.05 * math.sqrt(2.0) / WHEEL_RADIUS  # rear-wheel mean -> 0.05 m/s
    pos_err: list[float] = []
    head_err: list[float] = []
    for k in range(int(duration * ODO_RATE) + 1):
        t = k / ODO_RATE
        tr = truth_at(t)
        spins = tr.speed / WHEEL_RADIUS + rng.normal(0.0, spin_sigma, 4)
        loc.on_odometry(
            Odometry(
                t=t,
                wheel_speeds=(spins[0], spins[1], spins[2], spins[3]),
                wheel_radius=WHEEL_RADIUS,
                yaw_rate=tr.yaw_rate + rng.normal(0.0, 0.005),
                steering_angle=0.0,
            )
        )
        if k % GNSS_EVERY == 0:
            loc.on_gnss(
                GnssFix(
                    t=t,
                    x=tr.x + bias[0] + rng.normal(0.0, gnss_sigma),
                    y=tr.y + bias[1] + rng.normal(0.0, gnss_sigma),
                    heading=wrap_angle(tr.heading + rng.normal(0.0, heading_sigma)),
                    sigma=gnss_sigma,
                    heading_sigma=heading_sigma,
                )
            )
        if t < SETTLE:
            continue
        est = loc.estimate(t)
        pos_err.append(math.hypot(est.x - tr.x - bias[0], est.y - tr.y - bias[1]))
        head_err.append(wrap_angle(est.heading - tr.heading))
    return np.array(pos_err), np.array(head_err)


def rms(a: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(a))))


DURATION = T_STRAIGHT + 2.0 * math.pi * RADIUS / SPEED + 2.0  # [s] a full circle and more


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_rms_errors_on_straight_then_circle(seed: int) -> None:
    pos_err, head_err = run(seed, DURATION)
    assert rms(pos_err) < 0.03
    assert rms(head_err) < 0.15 * DEG
    # the error never blows up at the straight -> circle step or the +-pi wrap
    assert float(np.max(pos_err)) < 0.12
    assert float(np.max(np.abs(head_err))) < 0.6 * DEG


def test_estimate_follows_constant_gnss_bias() -> None:
    """A constant bias cannot be observed from odometry: the estimate follows the fixes."""
    pos_err, head_err = run(seed=7, duration=20.0, bias=(1.5, -0.8))
    assert rms(pos_err) < 0.03
    assert rms(head_err) < 0.15 * DEG


def test_speed_and_yaw_rate_estimated() -> None:
    loc = Localizer()
    for k in range(int(15.0 * ODO_RATE)):
        t = k / ODO_RATE
        tr = truth_at(t)
        spin = tr.speed / WHEEL_RADIUS
        loc.on_odometry(Odometry(t, (spin, spin, spin, spin), WHEEL_RADIUS, tr.yaw_rate, 0.1))
        if k % GNSS_EVERY == 0:
            loc.on_gnss(GnssFix(t, tr.x, tr.y, tr.heading, 0.05, 0.2 * DEG))
    est = loc.estimate(t)
    assert est.speed == pytest.approx(SPEED, abs=0.01)
    assert est.yaw_rate == pytest.approx(SPEED / RADIUS, abs=0.002)
    assert est.steering_angle == 0.1
    # no camera: the position is known no better than the receiver's stated 5 cm (its bias
    # and its position cannot be told apart)
    assert 0.04 < est.position_sigma < 0.06


def test_not_initialised_until_first_fix_and_reset() -> None:
    loc = Localizer()
    loc.on_odometry(Odometry(0.0, (30.0, 30.0, 30.0, 30.0), WHEEL_RADIUS, 0.1, 0.0))
    assert not loc.initialised
    with pytest.raises(NotInitialisedError):
        loc.estimate(0.0)
    loc.on_gnss(GnssFix(0.0, 1.0, 2.0, math.pi, 0.05, 0.2 * DEG))
    est = loc.estimate(0.0)
    assert (est.x, est.y, est.heading) == (1.0, 2.0, math.pi)
    assert est.speed == pytest.approx(30.0 * WHEEL_RADIUS)  # from the odometry before it
    assert est.yaw_rate == pytest.approx(0.1)
    loc.reset()
    assert not loc.initialised


def test_heading_innovation_wrapped() -> None:
    """A fix at -pi + eps after a state at pi - eps moves the heading by 2 eps, not 2 pi."""
    loc = Localizer(LocalizerParams())
    loc.on_gnss(GnssFix(0.0, 0.0, 0.0, math.pi - 0.001, 0.05, 0.2 * DEG))
    loc.on_gnss(GnssFix(0.1, 0.0, 0.0, -math.pi + 0.001, 0.05, 0.2 * DEG))
    h = loc.estimate(0.1).heading
    assert abs(wrap_angle(h - math.pi)) < 0.002
    assert -math.pi < h <= math.pi


def test_motion_jacobian_matches_finite_differences() -> None:
    x = np.array([3.0, -2.0, 0.7, 11.0, 0.3])
    dt = 0.025
    _, f = motion(x, dt)
    eps = 1e-6
    for j in range(5):
        dx = np.zeros(5)
        dx[j] = eps
        num = (motion(x + dx, dt)[0] - motion(x - dx, dt)[0]) / (2 * eps)
        np.testing.assert_allclose(f[:, j], num, atol=1e-7)


@pytest.mark.parametrize(("spins", "expected"), [
    ((50.0, 50.0, 50.0, 50.0), 50.0),  # rolling
    ((50.5, 49.5, 50.5, 49.5), 50.0),  # a curve: the rear mean
    ((50.0, 50.0, 52.0, 50.0), 51.0),  # a flat rear tyre spins 4 % faster: still the mean
    ((58.0, 45.0, 50.0, 38.0), 44.0),  # a 5 m right turn: the inner rear 35 % slower
    ((41.2, 41.3, 0.0, 0.0), 41.3),  # ALKS 4.2.3's emergency stop: the rear wheels locked
    ((42.4, 42.4, 1.9, 3.2), 42.4),  # locking
    ((46.8, 46.8, 34.9, 36.9), 35.9),  # beginning to lock: 25 % slower, not yet taken
    ((0.0, 0.0, 0.0, 0.0), 0.0),  # standing
])
def test_a_locking_wheel_does_not_stop_the_car_in_the_estimate(
        spins: tuple[float, float, float, float], expected: float) -> None:
    """Under hard braking a locked wheel reads 0 while the car slides on: the speed is the
    fastest wheel's (an ABS's reference speed), not the rear mean (which said 0.1 m/s at
    13.6 m/s, and the control FSM took the car for stopped)."""
    odo = Odometry(t=0.0, wheel_speeds=spins, wheel_radius=0.33, yaw_rate=0.0,
                   steering_angle=0.0)
    assert wheel_speed(odo, LocalizerParams().wheel_lock_ratio) == pytest.approx(
        expected * 0.33)


def test_motion_jacobian_with_the_lever_matches_finite_differences() -> None:
    x = np.array([3.0, -2.0, 0.7, 11.0, 0.3])
    dt = 0.025
    _, f = motion(x, dt, 1.35)
    eps = 1e-6
    for j in range(5):
        dx = np.zeros(5)
        dx[j] = eps
        num = (motion(x + dx, dt, 1.35)[0] - motion(x - dx, dt, 1.35)[0]) / (2 * eps)
        np.testing.assert_allclose(f[:, j], num, atol=1e-7)


REAR_AXLE = 1.35  # [m] the car's centre ahead of its rear axle


def dead_reckon_turn(turn: float, radius: float, rear_axle: float) -> tuple[float, float]:
    """A town turn through ``turn`` [rad] of ``radius`` [m] at the rear axle, 6 m/s there,
    between 1 s straights, in a GNSS outage after the first fix: the estimate is odometry
    alone. Returns (position error [m], heading error [rad]) of the car's centre at the end."""
    v = 6.0  # [m/s] the rear axle's speed
    w = math.copysign(v / radius, turn)  # [rad/s] in the turn
    t_turn = turn / w
    loc = Localizer(LocalizerParams(rear_axle=rear_axle))
    rear = np.zeros(2)
    psi = 0.0

    def centre() -> np.ndarray:
        return rear + REAR_AXLE * np.array([math.cos(psi), math.sin(psi)])

    c0 = centre()
    spin = v / WHEEL_RADIUS
    loc.on_odometry(Odometry(0.0, (spin, spin, spin, spin), WHEEL_RADIUS, 0.0, 0.0))
    loc.on_gnss(GnssFix(0.0, float(c0[0]), float(c0[1]), 0.0, 0.05, 0.001))
    dt = 1.0 / ODO_RATE
    steps = round((2.0 + t_turn) * ODO_RATE)
    def rate_after(t: float) -> float:  # [rad/s] over the step that starts at t
        return w if 1.0 < t + 0.5 * dt < 1.0 + t_turn else 0.0

    for k in range(1, steps + 1):
        t = k * dt
        rate = rate_after(t - dt)  # the gyro read it at the step's start
        a = psi + 0.5 * rate * dt  # exact chord of the rear axle's arc
        chord = v * dt if rate == 0.0 else 2.0 * v / rate * math.sin(0.5 * rate * dt)
        rear = rear + chord * np.array([math.cos(a), math.sin(a)])
        psi += rate * dt
        loc.on_odometry(Odometry(t, (spin, spin, spin, spin), WHEEL_RADIUS, rate_after(t),
                                 0.0))
    est = loc.estimate(steps * dt)
    c = centre()
    return math.hypot(est.x - c[0], est.y - c[1]), abs(wrap_angle(est.heading - psi))


@pytest.mark.parametrize(("turn", "radius"), [(math.pi / 2, 10.0), (-math.pi / 2, 8.0),
                                              (math.pi, 5.25)])
def test_the_centre_ahead_of_the_rear_axle_is_dead_reckoned_through_a_turn(
        turn: float, radius: float) -> None:
    """Through a junction's turn the camera sees no line: the pose is dead reckoning. The
    rear wheels give the rear axle's speed; the centre, 1.35 m ahead, swings out by
    2 x 1.35 x sin(turn / 2) (1.9 m for a right angle, 2.7 m for a U-turn) unless the
    motion model carries it."""
    swing = 2.0 * REAR_AXLE * abs(math.sin(turn / 2))  # [m]
    error, heading_error = dead_reckon_turn(turn, radius, REAR_AXLE)
    assert error < 0.1 * swing  # left: the gyro's step at the turn's ends, one sample
    assert heading_error < 1e-3
    unmodelled = dead_reckon_turn(turn, radius, 0.0)[0]
    assert unmodelled == pytest.approx(swing, abs=0.2)
