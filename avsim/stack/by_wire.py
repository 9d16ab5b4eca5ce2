"""Commands from a steering angle and a longitudinal acceleration (`drive_by_wire`), or from
pedal positions (`by_pedals`): the car's drive-by-wire interfaces, for stacks that plan
accelerations or pedals, not wheel torques.

The acceleration becomes wheel torques by the bundled controller's point-mass inverse model
(`control.actuation`): F = m a + F_roll + F_drag(v), drive torque F r for F >= 0, brake
torque -F r otherwise, each within the actuators' limits. It is open loop: grade, rotating
inertia and tyre slip are not in it, so the car's acceleration follows the request only as
well as the model holds (a stack closes the loop on the odometry's speed).
"""

from __future__ import annotations

from control import VehicleCommand, VehicleParams, wheel_torques
from world.frames import Indicator, VehicleInfo


def drive_by_wire(steering_angle: float, accel: float, speed: float, vehicle: VehicleInfo,
                  hazard_lights: bool = False,
                  indicator: Indicator = Indicator.OFF) -> VehicleCommand:
    """The command for road-wheel angle `steering_angle` [rad] (left +) and longitudinal
    acceleration `accel` [m/s^2] at forward `speed` [m/s] of the car `vehicle`."""
    torques = wheel_torques(accel, speed, VehicleParams(mass=vehicle.mass,
                                                        wheel_radius=vehicle.wheel_radius))
    return VehicleCommand(steering_angle, torques.drive, torques.brake, accel, hazard_lights,
                          indicator)


PEDALS = VehicleParams(mass=1.0, wheel_radius=1.0)  # the actuators' limits: the pedals'
#   full travel is `max_drive_torque` [N m] and `max_brake_torque` [N m]


def by_pedals(steering_angle: float, throttle: float, brake: float,
              hazard_lights: bool = False,
              indicator: Indicator = Indicator.OFF) -> VehicleCommand:
    """The command for road-wheel angle `steering_angle` [rad] (left +), the accelerator
    pedal `throttle` and the brake pedal `brake` (each 0 to 1, clamped): drive torque
    `throttle` x the drive's limit (3000 N m, total at the driven wheels), brake torque
    `brake` x the brakes' (5000 N m, total); the brake pedal wins when both are pressed
    (the car's brake override), and the acceleration logged is NaN (not planned)."""
    throttle, brake = min(max(throttle, 0.0), 1.0), min(max(brake, 0.0), 1.0)
    drive = 0.0 if brake > 0.0 else throttle * PEDALS.max_drive_torque
    return VehicleCommand(steering_angle, drive, brake * PEDALS.max_brake_torque,
                          float("nan"), hazard_lights, indicator)
