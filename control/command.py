"""What control hands to the world, and the interfaces of the controller stage and of a
whole driving stack (`ControllerStage`, `DrivingStack`). A leaf module: dataclasses and
protocols only."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Protocol

from perception.messages import PerceptionReport
from planner.messages import Plan
from world.frames import Frames, Indicator

__all__ = ["ControllerStage", "DrivingStack", "StackStep", "VehicleCommand"]


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
    indicator: Indicator = Indicator.OFF  # the turn indicators


class ControllerStage(Protocol):
    """The controller stage: `Plan` in, `VehicleCommand` out, once per control tick."""

    def update(self, plan: Plan, dt: float) -> VehicleCommand:
        """The command for `plan`, held for the control period `dt` [s]."""


@dataclass(frozen=True, slots=True, eq=False)
class StackStep:
    """What a driving stack returns at a control tick: the command, and what it may show of
    itself: its plan (the runner logs and records the plan's targets and states), and named
    diagnostic channels (numbers the recording plots, by name)."""

    command: VehicleCommand
    plan: Plan | None = None
    channels: Mapping[str, float] = field(default_factory=dict)


class DrivingStack(Protocol):
    """A whole stack: sensor frames in, a command out.

    The runner calls `on_frames` with each delivery, in time order, then `tick` once per
    control tick (after that tick's deliveries)."""

    @property
    def reads(self) -> frozenset[str] | None:
        """The names of the sensors whose frames it uses (None: all)."""

    def on_frames(self, t: float, frames: Frames) -> PerceptionReport | None:
        """One delivery: `frames` captured together at time `t` [s], by sensor name; a
        perception report for scoring and the recording, or None."""

    def tick(self, t: float, dt: float) -> StackStep:
        """The step for the control tick at time `t` [s], held for `dt` [s]."""
