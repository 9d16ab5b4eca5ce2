"""Acceleration request -> drive / brake torque: signs, magnitudes, deadband, limits, hold."""

from __future__ import annotations

import itertools

import pytest

from control.actuation import GRAVITY, VehicleParams, longitudinal_force, wheel_torques

P = VehicleParams(mass=1500.0, wheel_radius=0.33)  # the example car of the figures below
F_ROLL = 0.012 * 1500.0 * GRAVITY  # [N] ~176.6


def f_drag(v: float) -> float:
    return 0.5 * 1.225 * 0.7 * v * v


@pytest.mark.parametrize("speed", [0.0, 10.0, 15.0])
def test_drive_torque_for_2_mps2(speed: float) -> None:
    torques = wheel_torques(2.0, speed, P)
    assert torques.drive == pytest.approx((3000.0 + F_ROLL + f_drag(speed)) * 0.33)
    assert torques.brake == 0.0


def test_brake_torque_for_minus_3_mps2() -> None:
    torques = wheel_torques(-3.0, 10.0, P)
    assert torques.drive == 0.0
    assert torques.brake == pytest.approx((4500.0 - F_ROLL - f_drag(10.0)) * 0.33)


def test_zero_request_holds_speed_against_resistance() -> None:
    torques = wheel_torques(0.0, 12.0, P)
    assert torques.drive == pytest.approx((F_ROLL + f_drag(12.0)) * 0.33)


def test_gentle_deceleration_is_left_to_the_resistances() -> None:
    # the car's own resistance gives -F_roll / m ~ -0.118 m/s^2 at low speed: no brake needed
    torques = wheel_torques(-0.1, 1.0, P)
    assert torques.drive == 0.0
    assert torques.brake == 0.0


def test_deadband_coasts_around_zero_force() -> None:
    a_balance = -longitudinal_force(0.0, 5.0, P) / P.mass  # [m/s^2] request with F = 0
    for delta in (-0.03, -0.01, 0.0, 0.01, 0.03):  # |m delta| <= 45 N < 50 N deadband
        torques = wheel_torques(a_balance + delta, 5.0, P)
        assert (torques.drive, torques.brake) == (0.0, 0.0)
    assert wheel_torques(a_balance + 0.04, 5.0, P).drive > 0.0
    assert wheel_torques(a_balance - 0.04, 5.0, P).brake > 0.0


def test_torques_are_clamped_to_the_actuator_limits() -> None:
    assert wheel_torques(10.0, 15.0, P).drive == P.max_drive_torque
    assert wheel_torques(-20.0, 15.0, P).brake == P.max_brake_torque


def test_hold_forbids_drive() -> None:
    assert wheel_torques(-3.0, 0.0, P, hold=True).brake == pytest.approx((4500.0 - F_ROLL) * 0.33)
    held = wheel_torques(0.5, 0.0, P, hold=True)
    assert held.drive == 0.0


def test_never_drive_and_brake_together_and_never_negative() -> None:
    for accel, speed in itertools.product([-8, -3, -0.5, -0.1, 0, 0.1, 1, 6], [0, 0.2, 5, 15]):
        torques = wheel_torques(accel, speed, P)
        assert torques.drive >= 0.0
        assert torques.brake >= 0.0
        assert torques.drive == 0.0 or torques.brake == 0.0
