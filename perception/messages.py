"""What perception hands to the planner. A leaf module: dataclasses only."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class EgoState:
    """The stack's own estimate of the car's state (fused GNSS + odometry)."""

    t: float  # [s] sim time of the estimate
    x: float  # [m] map frame, car centre
    y: float  # [m] map frame, car centre
    heading: float  # [rad] yaw, counter-clockwise from +x, in (-pi, pi]
    speed: float  # [m/s] forward speed
    yaw_rate: float  # [rad/s]
    steering_angle: float  # [rad] measured road-wheel angle (bicycle), left +
    position_sigma: float  # [m] 1-sigma of the position estimate
