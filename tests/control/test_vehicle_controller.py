"""VehicleController: composition, command fields, hint handling, hold, reset."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from control.command import VehicleCommand
from control.longitudinal import SpeedController
from control.stanley import StanleyPid
from control.vehicle_controller import VehicleController
from perception.messages import EgoState
from planner.messages import Plan, ReferencePath
from tests.control.paths import straight
from tests.vehicle import controller_params

DT = 1.0 / 40.0  # [s]


def plan(
    path: ReferencePath,
    x: float = 0.0,
    y: float = 0.0,
    speed: float = 10.0,
    target_speed: float = 10.0,
    steering_angle: float = 0.0,
) -> Plan:
    ego = EgoState(
        t=0.0,
        x=x,
        y=y,
        heading=0.0,
        speed=speed,
        yaw_rate=0.0,
        steering_angle=steering_angle,
        position_sigma=0.1,
    )
    return Plan(
        t=0.0,
        ego=ego,
        path=path,
        target_speed=target_speed,
        target_accel=0.0,
        speed_limit=15.0,
        station=0.0,
        lateral_error=-y,
    )


def test_composes_a_lateral_and_a_longitudinal_controller() -> None:
    controller = VehicleController(controller_params())
    assert isinstance(controller.lateral, StanleyPid)
    assert isinstance(controller.longitudinal, SpeedController)
    assert type(controller).__mro__ == (VehicleController, object)


def test_command_on_the_path_at_speed() -> None:
    command = VehicleController(controller_params()).update(plan(straight(50.0)), DT)
    assert isinstance(command, VehicleCommand)
    assert command.steering_angle == pytest.approx(0.0)
    assert command.drive_torque > 0.0  # holds speed against rolling resistance and drag
    assert command.brake_torque == 0.0


def test_left_of_path_steers_right_and_too_fast_brakes() -> None:
    controller = VehicleController(controller_params())
    for _ in range(40):
        command = controller.update(plan(straight(50.0), y=0.5, speed=14.0), DT)
    assert command.steering_angle < 0.0
    assert command.accel_request < 0.0
    assert command.brake_torque > 0.0
    assert command.drive_torque == 0.0


def test_hint_is_kept_on_the_same_path_and_dropped_for_a_new_one() -> None:
    controller = VehicleController(controller_params())
    loop = straight(100.0)
    controller.update(plan(loop, x=20.0), DT)
    assert controller.last_error is not None
    first = controller.last_error.index
    controller.update(plan(loop, x=20.5), DT)
    assert controller.last_error.index == first + 1
    # a re-planned path starting at the car: the old index is meaningless on it
    replanned = straight(50.0, start=(20.0, 0.0))
    controller.update(plan(replanned, x=21.0), DT)
    assert controller.last_error.index == math.floor((1.0 + 1.35) / 0.5)


def test_hint_follows_the_car_onto_the_second_lap_of_a_looped_path() -> None:
    radius, n = 20.0, 240  # one lap sampled at 240 points, then the same points again
    a = np.arange(n) * math.tau / n
    lap = np.column_stack([radius * np.sin(a), radius * (1.0 - np.cos(a))])
    path = ReferencePath(
        xy=np.concatenate([lap, lap]),  # bit-identical laps
        heading=np.concatenate([a, a]),
        curvature=np.full(2 * n, 1.0 / radius),
    )
    controller = VehicleController(controller_params())
    for k in range(int(1.5 * n)):
        angle = k * math.tau / n  # car centre on the circle, heading along it
        ego_plan = plan(path, x=radius * math.sin(angle), y=radius * (1.0 - math.cos(angle)))
        ego = replace(ego_plan.ego, heading=math.remainder(angle, math.tau))
        controller.update(replace(ego_plan, ego=ego), DT)
    assert controller.last_error is not None
    # a full search would return the first lap (the points are identical, argmin takes the first)
    assert controller.last_error.index > n


def test_standstill_hold_brakes_without_drive() -> None:
    controller = VehicleController(controller_params())
    for _ in range(40):
        command = controller.update(plan(straight(50.0), speed=0.0, target_speed=0.0), DT)
    assert command.drive_torque == 0.0
    assert command.brake_torque > 1000.0
    assert command.accel_request == pytest.approx(-3.0)


def test_first_update_rate_limits_from_the_measured_steering_angle() -> None:
    controller = VehicleController(controller_params())
    command = controller.update(plan(straight(50.0), steering_angle=0.3), DT)
    assert command.steering_angle == pytest.approx(0.3 - 0.9 * DT)
    controller.reset()
    assert controller.last_error is None
    command = controller.update(plan(straight(50.0), steering_angle=-0.2), DT)
    assert command.steering_angle == pytest.approx(-0.2 + 0.9 * DT)
