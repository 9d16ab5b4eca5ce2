"""What control hands to the world. A leaf module: one dataclass."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["VehicleCommand"]


@dataclass(frozen=True, slots=True)
class VehicleCommand:
    """One control tick's actuator command.

    At most one of `drive_torque` and `brake_torque` is non-zero.
    """

    steering_angle: float  # [rad] road-wheel angle of the bicycle model, left +
    drive_torque: float  # [N m] total at the driven wheels, >= 0
    brake_torque: float  # [N m] total over all wheels, >= 0
    accel_request: float  # [m/s^2] longitudinal acceleration behind the torques (for logging)
    hazard_lights: bool = False  # the hazard lights flash
