"""Closed loop: VehicleController steering a kinematic bicycle along straights and arcs.

The model (written here, independent of the controller): rear-axle kinematic bicycle,
wheelbase 2.7 m, the road-wheel angle following the command through a first-order lag of
0.1 s; the car's reference point (what the controller is told) is the centre, L/2 ahead of
the rear axle. Speed is held constant. Control runs at 40 Hz, the model at 240 Hz (the
physics rate). Errors are measured from the true geometry at the front axle, not from the
controller's own projection.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import pytest

from control.vehicle_controller import VehicleController, VehicleControllerParams
from perception.messages import EgoState
from planner.messages import Plan, ReferencePath
from tests.control.paths import straight, straight_then_arc
from tests.vehicle import controller_params, stanley_params

WHEELBASE = 2.7  # [m]
STEER_LAG = 0.1  # [s] first-order time constant of the steering actuator
PHYSICS_DT = 1.0 / 240.0  # [s]
CONTROL_DT = 1.0 / 40.0  # [s]


@dataclass
class KinematicBicycle:
    """Rear-axle kinematic bicycle with a lagged steering angle."""

    x: float  # [m] rear axle
    y: float  # [m] rear axle
    heading: float  # [rad]
    speed: float  # [m/s]
    steer: float = 0.0  # [rad] road-wheel angle, left +

    @classmethod
    def from_centre(cls, x: float, y: float, heading: float, speed: float) -> KinematicBicycle:
        half = WHEELBASE / 2
        return cls(x - half * math.cos(heading), y - half * math.sin(heading), heading, speed)

    @property
    def yaw_rate(self) -> float:
        return self.speed * math.tan(self.steer) / WHEELBASE

    def point(self, ahead: float) -> tuple[float, float]:
        """[m] the point `ahead` of the rear axle on the car's axis."""
        return self.x + ahead * math.cos(self.heading), self.y + ahead * math.sin(self.heading)

    def step(self, steer_command: float, dt: float) -> None:
        for _ in range(round(dt / PHYSICS_DT)):
            self.steer += (steer_command - self.steer) * PHYSICS_DT / STEER_LAG
            self.x += self.speed * math.cos(self.heading) * PHYSICS_DT
            self.y += self.speed * math.sin(self.heading) * PHYSICS_DT
            self.heading += self.yaw_rate * PHYSICS_DT


def plan_for(car: KinematicBicycle, path: ReferencePath, t: float) -> Plan:
    cx, cy = car.point(WHEELBASE / 2)
    ego = EgoState(
        t=t,
        x=cx,
        y=cy,
        heading=math.remainder(car.heading, math.tau),
        speed=car.speed,
        yaw_rate=car.yaw_rate,
        steering_angle=car.steer,
        position_sigma=0.0,
    )
    return Plan(
        t=t,
        ego=ego,
        path=path,
        target_speed=car.speed,
        target_accel=0.0,
        speed_limit=15.0,
        station=0.0,
        lateral_error=0.0,
    )


def drive(
    path: ReferencePath,
    car: KinematicBicycle,
    duration: float,
    true_error: Callable[[float, float], float],
    params: VehicleControllerParams | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run the loop; return time [s], distance travelled [m] and the true front-axle error [m]
    after each control tick, and check the steering command's limits on the way."""
    controller = VehicleController(params if params is not None else controller_params())
    lat = controller.params.lateral
    times, travelled, errors = [], [], []
    t, previous = 0.0, 0.0
    while t < duration:
        command = controller.update(plan_for(car, path, t), CONTROL_DT)
        assert abs(command.steering_angle) <= lat.max_steer + 1e-12
        assert abs(command.steering_angle - previous) <= lat.max_steer_rate * CONTROL_DT + 1e-9
        previous = command.steering_angle
        car.step(command.steering_angle, CONTROL_DT)
        t += CONTROL_DT
        times.append(t)
        travelled.append(car.speed * t)
        errors.append(true_error(*car.point(WHEELBASE)))
    return np.array(times), np.array(travelled), np.array(errors)


def circle_error(
    centre_x: float, centre_y: float, radius: float
) -> Callable[[float, float], float]:
    return lambda x, y: math.hypot(x - centre_x, y - centre_y) - radius


@pytest.mark.parametrize(("offset", "speed"), [(1.0, 10.0), (-1.0, 10.0), (1.0, 3.0)])
def test_straight_offset_converges_within_30_m(offset: float, speed: float) -> None:
    car = KinematicBicycle.from_centre(0.0, offset, 0.0, speed)
    _, travelled, errors = drive(straight(200.0), car, 80.0 / speed, lambda _x, y: y)
    after = np.abs(errors[travelled >= 30.0])
    assert after.max() < 0.05
    # no large swing to the other side on the way in
    assert (errors * np.sign(offset)).min() > -0.05


@pytest.mark.parametrize("left", [True, False])
def test_circle_r60_at_12_mps_steady_state(left: bool) -> None:
    radius, speed = 60.0, 12.0
    path = straight_then_arc(0.0, radius, 1.9 * math.pi, left=left)
    car = KinematicBicycle.from_centre(0.0, 0.0, 0.0, speed)
    error = circle_error(0.0, radius if left else -radius, radius)
    times, _, errors = drive(path, car, 25.0, error)
    steady = np.abs(errors[times >= 15.0])
    assert steady.max() < 0.05


def test_curvature_feed_forward_on_top_of_eq1_double_counts_the_arc() -> None:
    """Why `k_ff` defaults to 0: the front-axle heading term already holds the arc's steer."""
    radius, speed = 60.0, 12.0
    lateral = replace(stanley_params(), k_ff=1.0, ki=0.0)
    params = controller_params(lateral=lateral)
    path = straight_then_arc(0.0, radius, 1.9 * math.pi)
    car = KinematicBicycle.from_centre(0.0, 0.0, 0.0, speed)
    times, _, errors = drive(path, car, 25.0, circle_error(0.0, radius, radius), params)
    steady = errors[times >= 15.0]
    # radius error < 0: inside the left turn, i.e. left of the path, e_fa ~ -(v+k_soft) L k / kp
    predicted = (speed + lateral.k_soft) * WHEELBASE / radius / lateral.kp
    assert steady.mean() == pytest.approx(-predicted, rel=0.1)


@pytest.mark.parametrize("left", [True, False])
def test_straight_to_arc_transition_at_12_mps(left: bool) -> None:
    radius, speed, straight_length = 60.0, 12.0, 100.0
    path = straight_then_arc(straight_length, radius, math.pi / 2, left=left)
    car = KinematicBicycle.from_centre(0.0, 0.0, 0.0, speed)
    arc = circle_error(straight_length, radius if left else -radius, radius)

    def error(x: float, y: float) -> float:
        return y if x < straight_length else arc(x, y)

    _, _, errors = drive(path, car, (straight_length + 0.95 * radius * math.pi / 2) / speed, error)
    assert np.abs(errors).max() < 0.25
