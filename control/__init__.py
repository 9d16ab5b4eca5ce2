"""Vehicle control: Stanley + PID steering (ICCAS 2020 Eq. 1), speed PID, wheel torques.

Imports only `planner.messages`; returns a plain `VehicleCommand`.
"""

from __future__ import annotations

# First: the `world` package holds numpy's SIMD dispatch at x86-64-v3 before numpy is
# imported (the same numbers whichever package a program imports first).
import world.frames  # noqa: F401

# isort: split
from control.actuation import VehicleParams, WheelTorques, longitudinal_force, wheel_torques
from control.command import VehicleCommand
from control.longitudinal import SpeedCommand, SpeedController, SpeedParams
from control.pid import Pid, PidParams
from control.stanley import (
    MAX_STEER,
    FrontAxleError,
    StanleyParams,
    StanleyPid,
    front_axle_error,
)
from control.vehicle_controller import VehicleController, VehicleControllerParams

__all__ = [
    "MAX_STEER",
    "FrontAxleError",
    "Pid",
    "PidParams",
    "SpeedCommand",
    "SpeedController",
    "SpeedParams",
    "StanleyParams",
    "StanleyPid",
    "VehicleCommand",
    "VehicleController",
    "VehicleControllerParams",
    "VehicleParams",
    "WheelTorques",
    "front_axle_error",
    "longitudinal_force",
    "wheel_torques",
]
