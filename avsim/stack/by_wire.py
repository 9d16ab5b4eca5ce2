"""A command from a steering angle and a longitudinal acceleration (`drive_by_wire`): the
car's drive-by-wire interface, for stacks that plan accelerations, not wheel torques.

The acceleration becomes wheel torques by the bundled controller's point-mass inverse model
(`control.actuation`): F = m a + F_roll + F_drag(v), drive torque F r for F >= 0, brake
torque -F r otherwise, each within the actuators' limits. It is open loop: grade, rotating
inertia and tyre slip are not in it, so the car's acceleration follows the request only as
well as the model holds (a stack closes the loop on the odometry's speed).
"""

from __future__ import annotations

from control import VehicleCommand, VehicleParams, wheel_torques
from world.frames import VehicleInfo


def drive_by_wire(steering_angle: float, accel: float, speed: float, vehicle: VehicleInfo,
                  hazard_lights: bool = False) -> VehicleCommand:
    """The command for road-wheel angle `steering_angle` [rad] (left +) and longitudinal
    acceleration `accel` [m/s^2] at forward `speed` [m/s] of the car `vehicle`."""
    torques = wheel_torques(accel, speed, VehicleParams(mass=vehicle.mass,
                                                        wheel_radius=vehicle.wheel_radius))
    return VehicleCommand(steering_angle, torques.drive, torques.brake, accel, hazard_lights)
