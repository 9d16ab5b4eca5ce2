"""The vehicle controller: a lateral and a longitudinal controller side by side.

Composition, as in CARLA's agents (`VehiclePIDController` has a lateral and a longitudinal
controller): `VehicleController` *has* a `StanleyPid` and a `SpeedController` and maps the
speed loop's acceleration request to wheel torques. Per tick (`update(plan, dt)`):

1. project the front axle onto `plan.path` (`front_axle_error`), searching near the index
   kept from the previous tick when the plan carries the same path object, else the whole
   path (a re-planned path is a new object and the old index means nothing on it);
2. steer with Stanley + PID (ICCAS 2020 Eq. 1);
3. request an acceleration from the speed loop (target speed and feed-forward acceleration);
4. turn it into drive or brake torque.

It reads only `plan` (whose `ego` is the stack's own state estimate), never the simulator.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from control.actuation import VehicleParams, wheel_torques
from control.command import VehicleCommand
from control.longitudinal import SpeedController, SpeedParams
from control.stanley import FrontAxleError, StanleyParams, StanleyPid, front_axle_error
from planner.messages import ControlState, HazardLights, Plan, ReferencePath
from world.frames import Indicator

__all__ = ["VehicleController", "VehicleControllerParams"]


@dataclass(frozen=True, slots=True)
class VehicleControllerParams:
    """Parameters of the three parts."""

    lateral: StanleyParams
    vehicle: VehicleParams
    longitudinal: SpeedParams = field(default_factory=SpeedParams)


class VehicleController:
    """Plan in, `VehicleCommand` out; keeps the path hint index between ticks."""

    def __init__(self, params: VehicleControllerParams) -> None:
        self.params = params
        self.lateral = StanleyPid(self.params.lateral)
        self.longitudinal = SpeedController(self.params.longitudinal)
        self._path: ReferencePath | None = None  # the path `_hint` indexes
        self._hint: int | None = None  # [-] last matched segment on `_path`
        self._fresh = True  # the next update starts the steering rate limit from the ego's
        self._last_error: FrontAxleError | None = None

    @property
    def last_error(self) -> FrontAxleError | None:
        """The last tick's front-axle error (for logging), None before the first update."""
        return self._last_error

    def reset(self) -> None:
        """Forget all state; the next update starts from the measured steering angle."""
        self.lateral.reset()
        self.longitudinal.reset()
        self._path = None
        self._hint = None
        self._fresh = True
        self._last_error = None

    def update(self, plan: Plan, dt: float) -> VehicleCommand:
        """One control tick of `dt` [s] for `plan`; see the module docstring for the steps."""
        ego = plan.ego
        lat = self.params.lateral
        if self._fresh:
            self.lateral.reset(ego.steering_angle)
            self._fresh = False
        hint = self._hint if plan.path is self._path else None
        error = front_axle_error(
            plan.path,
            ego.x,
            ego.y,
            ego.heading,
            lat.wheelbase,
            hint_index=hint,
            centre_to_front_axle=lat.centre_to_front_axle,
        )
        self._path, self._hint, self._last_error = plan.path, error.index, error
        steer = self.lateral.update(error, ego.heading, ego.speed, ego.yaw_rate, dt)
        speed_cmd = self.longitudinal.update(
            plan.target_speed, plan.target_accel, ego.speed, dt,
            emergency=plan.control is ControlState.EMERGENCY_STOP)
        torques = wheel_torques(
            speed_cmd.accel, ego.speed, self.params.vehicle, hold=speed_cmd.hold
        )
        return VehicleCommand(
            steering_angle=steer,
            drive_torque=torques.drive,
            brake_torque=torques.brake,
            accel_request=speed_cmd.accel,
            hazard_lights=plan.hazard is HazardLights.ON,
            indicator=indicator(plan),
        )


def indicator(plan: Plan) -> Indicator:
    """The turn indicator of a lane change in hand (towards a lane of higher index: left;
    lower, the shoulder included: right), else off."""
    if plan.lane == plan.origin_lane:
        return Indicator.OFF
    return Indicator.LEFT if plan.lane > plan.origin_lane else Indicator.RIGHT
