"""The test car: the URDF's geometry (`CarGeometry`, the one source of the car's sizes) and
what each stage is configured with from it, as the stack's wiring does (`avsim.run.stack`)."""

from __future__ import annotations

from typing import Any

from control.actuation import VehicleParams
from control.stanley import StanleyParams
from control.vehicle_controller import VehicleControllerParams
from vehicle_urdf import read_geometry
from world.ego.body import vehicle_info

CAR = read_geometry()
VEHICLE = vehicle_info(CAR)  # the planner's and perception's view of it


def stanley_params(**changes: Any) -> StanleyParams:
    return StanleyParams(wheelbase=CAR.wheelbase, centre_to_front_axle=CAR.front_axle,
                         **changes)


def vehicle_params(**changes: Any) -> VehicleParams:
    return VehicleParams(mass=CAR.mass, wheel_radius=CAR.wheel_radius, **changes)


def controller_params(**changes: Any) -> VehicleControllerParams:
    changes.setdefault("lateral", stanley_params())
    changes.setdefault("vehicle", vehicle_params())
    return VehicleControllerParams(**changes)
