"""The bundled stack's stages, built from a `StackContext` (the factories `--perception`,
`--planner` and `--controller` name by default), and the perception stage of privileged
truth mode (`truth_perception`: `--perception avsim.stack.bundled:truth_perception
--privileged`)."""

from __future__ import annotations

from avsim.stack.context import StackContext
from control import (
    MAX_STEER,
    StanleyParams,
    VehicleController,
    VehicleControllerParams,
    VehicleParams,
)
from perception.perception import Perception, lane_camera
from perception.truth import TruthPerception
from planner.planner import MotionLayerParams, Planner, PlannerParams


def perception(ctx: StackContext) -> Perception:
    """Lanes from the front camera, objects from the LiDAR, the pose from GNSS, odometry and
    the lane (`perception.perception`)."""
    return Perception(ctx.road, ctx.vehicle, ctx.sensors, ctx.start_lane, ctx.timer)


def truth_perception(ctx: StackContext) -> TruthPerception:
    """Privileged truth mode only: the ground truth (`perception.truth`), the ego's state
    exactly and every object as a confirmed track; no camera lane (the planner keeps the
    map's lane)."""
    return TruthPerception(ctx.vehicle)


def planner(ctx: StackContext) -> Planner:
    """The motion and control FSMs with the ACC / event layer (`planner.planner`)."""
    return Planner(ctx.road, PlannerParams(
        set_speed=ctx.set_speed, max_speed=ctx.max_speed, vehicle=ctx.vehicle,
        lane=ctx.start_lane, camera=lane_camera(ctx.sensors) is not None,
        motion=MotionLayerParams(overtake=ctx.overtake)))


def controller(ctx: StackContext) -> VehicleController:
    """Stanley + PID steering and the speed PID to wheel torques (`control`)."""
    v = ctx.vehicle
    lateral = StanleyParams(wheelbase=v.wheelbase, centre_to_front_axle=v.front_axle,
                            max_steer=min(MAX_STEER, v.max_steer))
    return VehicleController(VehicleControllerParams(
        lateral=lateral, vehicle=VehicleParams(mass=v.mass, wheel_radius=v.wheel_radius)))
