"""Map an acceleration request to wheel drive and brake torques (point-mass inverse model).

    F = m * a + F_roll + F_drag(v)          [N] along the car's x axis
    F_roll = c_rr * m * g                   (the forward-only controller always rolls forward)
    F_drag = 0.5 * rho * CdA * v * |v|
    F >= 0  -> drive torque  F * r          [N m] total at the driven wheels
    F <  0  -> brake torque -F * r          [N m] total over all wheels

Resistances are added so that a = 0 holds speed instead of coasting down. Within
|F| < `deadband_force` both torques are 0 (the car coasts): the request hovering around the
resistance force would otherwise flip drive and brake every tick. While the speed loop holds
the car at a stop, drive torque is 0 whatever the request. Both torques are clamped to the
actuator limits. Rotating inertia and grade are not modelled; the speed PID's integrator takes
up what the model misses.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["VehicleParams", "WheelTorques", "longitudinal_force", "wheel_torques"]

GRAVITY = 9.81  # [m/s^2]


@dataclass(frozen=True, slots=True)
class VehicleParams:
    """The car as the longitudinal inverse model sees it (mass and wheel from its
    `CarGeometry`)."""

    mass: float  # [kg] total, with wheels
    wheel_radius: float  # [m] rolling radius
    rolling_resistance: float = 0.012  # [-] rolling resistance coefficient c_rr
    drag_area: float = 0.7  # [m^2] drag coefficient times frontal area, CdA
    air_density: float = 1.225  # [kg/m^3] sea level, 15 degC
    max_drive_torque: float = 3000.0  # [N m] total at the wheels (5 m/s^2 at 15 m/s needs ~2600)
    max_brake_torque: float = 5000.0  # [N m] total (~1 g of braking)
    deadband_force: float = 50.0  # [N] |F| below this commands neither drive nor brake


@dataclass(frozen=True, slots=True)
class WheelTorques:
    """Drive and brake torque; at most one is non-zero."""

    drive: float  # [N m] total at the driven wheels, >= 0
    brake: float  # [N m] total over all wheels, >= 0


def longitudinal_force(accel: float, speed: float, params: VehicleParams) -> float:
    """Force [N] at the tyres for `accel` [m/s^2] at `speed` [m/s]: m a + F_roll + F_drag."""
    rolling = params.rolling_resistance * params.mass * GRAVITY
    drag = 0.5 * params.air_density * params.drag_area * speed * abs(speed)
    return params.mass * accel + rolling + drag


def wheel_torques(
    accel: float, speed: float, params: VehicleParams, *, hold: bool = False
) -> WheelTorques:
    """Torques [N m] for an acceleration request `accel` [m/s^2] at forward `speed` [m/s].

    `hold` (standstill hold from the speed loop) forbids drive torque.
    """
    force = longitudinal_force(accel, speed, params)
    if abs(force) < params.deadband_force and not hold:
        return WheelTorques(drive=0.0, brake=0.0)
    if force >= 0.0 and not hold:
        return WheelTorques(
            drive=min(force * params.wheel_radius, params.max_drive_torque), brake=0.0
        )
    brake = min(max(-force, 0.0) * params.wheel_radius, params.max_brake_torque)
    return WheelTorques(drive=0.0, brake=brake)
