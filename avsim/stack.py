"""The driving stack, wired: perception (localisation) -> planner -> control.

It is fed only sensor frames (`GnssFix`, `Odometry`) and the static HD map, and returns a
`VehicleCommand`. The runner hands it frames at their rates and applies its command to the
ego's joints.
"""

from __future__ import annotations

from dataclasses import dataclass

from control.actuation import VehicleParams
from control.command import VehicleCommand
from control.stanley import StanleyParams
from control.vehicle_controller import VehicleController, VehicleControllerParams
from perception.localization import Localizer
from planner.lane_keeping import LaneKeepingParams, LaneKeepingPlanner
from planner.messages import Plan
from vehicle_urdf import CarGeometry
from world.frames import GnssFix, Odometry
from world.hdmap import RoadMap
from world.spec import EgoSpec


@dataclass(frozen=True, slots=True, eq=False)
class StackOutput:
    plan: Plan
    command: VehicleCommand


class Stack:
    """Localizer + lane-keeping planner + vehicle controller, built for one car and map."""

    def __init__(self, road: RoadMap, ego: EgoSpec, car: CarGeometry) -> None:
        self.localizer = Localizer()
        self.planner = LaneKeepingPlanner(
            road, LaneKeepingParams(set_speed=ego.set_speed, max_speed=ego.max_speed,
                                    lane=ego.lane)
        )
        lateral = StanleyParams(
            wheelbase=car.wheelbase, centre_to_front_axle=car.front_axle,
            max_steer=min(StanleyParams().max_steer, car.max_steer),
        )
        vehicle = VehicleParams(mass=car.mass, wheel_radius=car.wheel_radius)
        self.controller = VehicleController(
            VehicleControllerParams(lateral=lateral, vehicle=vehicle)
        )

    def on_gnss(self, fix: GnssFix) -> None:
        self.localizer.on_gnss(fix)

    def on_odometry(self, odo: Odometry) -> None:
        self.localizer.on_odometry(odo)

    def tick(self, t: float, dt: float) -> StackOutput:
        ego = self.localizer.estimate(t)
        plan = self.planner.update(ego)
        return StackOutput(plan, self.controller.update(plan, dt))
