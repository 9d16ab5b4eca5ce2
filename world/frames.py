"""Sensor data types: what the car's sensors hand to the stack.

This is a leaf module (no PyBullet, no numpy-heavy imports beyond types) so that
`perception/` may import it without reaching into the simulator.
Frames: the map frame is ENU-like, x east, y north, z up, yaw counter-clockwise from +x.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class GnssFix:
    """A GNSS position and heading fix, with the sensor's noise and bias already in it."""

    t: float  # [s] sim time of the measurement
    x: float  # [m] map frame, at the car's centre (base link origin)
    y: float  # [m] map frame
    heading: float  # [rad] yaw of the car's body, counter-clockwise from +x, in (-pi, pi]
    sigma: float  # [m] the receiver's stated 1-sigma horizontal accuracy
    heading_sigma: float  # [rad] the receiver's stated 1-sigma heading accuracy


@dataclass(frozen=True, slots=True)
class Odometry:
    """Wheel encoders, steering encoder and yaw-rate gyro, sampled together."""

    t: float  # [s] sim time of the measurement
    wheel_speeds: tuple[float, float, float, float]  # [rad/s] FL, FR, RL, RR spin rates
    wheel_radius: float  # [m] nominal rolling radius the car was built with
    yaw_rate: float  # [rad/s] gyro z, counter-clockwise positive
    steering_angle: float  # [rad] measured road-wheel angle (bicycle equivalent), left +

    @property
    def speed(self) -> float:
        """[m/s] forward speed from the mean rear-wheel spin (the undriven-by-steer axle)."""
        return 0.5 * (self.wheel_speeds[2] + self.wheel_speeds[3]) * self.wheel_radius
