"""The public stack API: everything a stack of one's own needs, in one import.

A stack is built by a factory from a `StackContext` (the static HD map, the car, its
sensors, what the driver asks) and is then driven by the runner:

- a whole stack (`DrivingStack`): `on_frames(t, frames)` with each delivery of sensor
  frames (a mapping from sensor name to `CameraFrame`, `LidarScan`, `GnssFix` or
  `Odometry`; in privileged truth mode also `GroundTruth`), then `tick(t, dt)` at every
  control tick, returning a `StackStep`: the `VehicleCommand`, optionally the `Plan` and
  named diagnostic channels;
- or stages, each replacing the bundled one: perception (`PerceptionStage`: frames in,
  `PlannerInput` out), planner (`PlannerStage`: `PlannerInput` in, `Plan` out), controller
  (`ControllerStage`: `Plan` in, `VehicleCommand` out). `drive_by_wire` makes a command from
a steering angle and an acceleration.

`--stack package.module:factory` (or `--perception`, `--planner`, `--controller`), or a
scenario file's `stack:` key, chooses them (`StackChoice`); an installed package names its
stack in the entry-point group ``avsim.stacks``. The types' units and frames are documented
where they are defined; docs/stack-api.md is the guide. A stack imports this module,
`world.frames` and `world.hdmap`, nothing else of avsim's.
"""

from __future__ import annotations

from avsim.stack.by_wire import by_pedals, drive_by_wire
from avsim.stack.choice import BUNDLED, GROUP, StackChoice, StackChoiceError, StackIdentity
from avsim.stack.context import API_VERSION, StackContext, Timer, untimed
from control.command import ControllerStage, DrivingStack, StackStep, VehicleCommand
from perception.messages import (
    Detection,
    EgoState,
    LaneEstimate,
    LaneView,
    LightDetection,
    PerceptionReport,
    PerceptionStage,
    PlannerInput,
    SensorHealth,
    SignView,
    Track,
)
from planner.messages import Lead, Plan, PlannerStage, ReferencePath
from world.frames import (
    CameraFrame,
    CameraInfo,
    DriverControls,
    Frame,
    Frames,
    GnssFix,
    GroundTruth,
    Indicator,
    LidarInfo,
    LidarScan,
    Odometry,
    SensorKind,
    SensorMount,
    SensorSpec,
    TruthObject,
    VehicleInfo,
)

__all__ = [
    "API_VERSION",
    "BUNDLED",
    "GROUP",
    "CameraFrame",
    "CameraInfo",
    "ControllerStage",
    "Detection",
    "DriverControls",
    "DrivingStack",
    "EgoState",
    "Frame",
    "Frames",
    "GnssFix",
    "GroundTruth",
    "Indicator",
    "LaneEstimate",
    "LaneView",
    "Lead",
    "LidarInfo",
    "LidarScan",
    "LightDetection",
    "Odometry",
    "PerceptionReport",
    "PerceptionStage",
    "Plan",
    "PlannerInput",
    "PlannerStage",
    "ReferencePath",
    "SensorHealth",
    "SensorKind",
    "SensorMount",
    "SensorSpec",
    "SignView",
    "StackChoice",
    "StackChoiceError",
    "StackContext",
    "StackIdentity",
    "StackStep",
    "Timer",
    "Track",
    "TruthObject",
    "VehicleCommand",
    "VehicleInfo",
    "by_pedals",
    "drive_by_wire",
    "untimed",
]
