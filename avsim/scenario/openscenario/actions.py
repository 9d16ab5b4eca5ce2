"""Private actions (OpenSCENARIO's PrivateAction choice) and their parts. Speeds in m/s,
distances in metres, times in seconds, angles in radians."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from avsim.scenario.openscenario.entities import Controller
from avsim.scenario.openscenario.entity_actions import LightStateAction, VisibilityAction
from avsim.scenario.openscenario.positions import Position
from avsim.scenario.openscenario.trajectories import Trajectory

DynamicsShape = Literal["step", "linear", "sinusoidal", "cubic"]
DynamicsDimension = Literal["rate", "time", "distance"]
FollowingMode = Literal["position", "follow"]


@dataclass(frozen=True, slots=True)
class TransitionDynamics:
    """How a value moves to its target: `value` is a rate ([unit/s], e.g. [m/s²] for a
    speed, [m/s] for a lane change's lateral speed), a time [s] or a distance [m]."""

    shape: DynamicsShape
    dimension: DynamicsDimension
    value: float  # [unit/s] | [s] | [m] by `dimension`
    following_mode: FollowingMode | None  # 1.2 attribute; None when not written


@dataclass(frozen=True, slots=True)
class TeleportAction:
    position: Position


@dataclass(frozen=True, slots=True)
class AbsoluteTargetSpeed:
    value: float  # [m/s]


@dataclass(frozen=True, slots=True)
class RelativeTargetSpeed:
    entity: str
    value: float  # [m/s] for delta, [-] for factor
    value_type: Literal["delta", "factor"]
    continuous: bool  # keep tracking the entity's speed


@dataclass(frozen=True, slots=True)
class SpeedAction:
    dynamics: TransitionDynamics
    target: AbsoluteTargetSpeed | RelativeTargetSpeed


@dataclass(frozen=True, slots=True)
class DynamicConstraints:
    max_acceleration: float | None  # [m/s²]
    max_deceleration: float | None  # [m/s²]
    max_speed: float | None  # [m/s]
    max_acceleration_rate: float | None  # [m/s³] (1.2)
    max_deceleration_rate: float | None  # [m/s³] (1.2)


@dataclass(frozen=True, slots=True)
class LongitudinalDistanceAction:
    """Keep a distance or a time gap (exactly one is set) to `entity`."""

    entity: str
    distance: float | None  # [m]
    time_gap: float | None  # [s]
    freespace: bool  # between bounding boxes (True) or reference points (False)
    continuous: bool
    coordinate_system: str  # entity, lane, road, trajectory (1.1+; default entity)
    displacement: str  # any, leadingReferencedEntity, trailingReferencedEntity (1.1+)
    constraints: DynamicConstraints | None


@dataclass(frozen=True, slots=True)
class SteadyState:
    """Where the actor of a SynchronizeAction reaches its final speed: `distance` [m] or
    `time` [s] before its target (exactly one is set)."""

    distance: float | None  # [m]
    time: float | None  # [s]


@dataclass(frozen=True, slots=True)
class FinalSpeed:
    """A SynchronizeAction's speed at the target: absolute [m/s], or the master's speed
    plus a delta [m/s] / times a factor [-]."""

    value: float  # [m/s] | [-]
    relative: Literal["absolute", "delta", "factor"]
    steady_state: SteadyState | None


@dataclass(frozen=True, slots=True)
class SynchronizeAction:
    """The actor reaches `target` when the master entity reaches `master_target`."""

    master: str
    master_target: Position
    target: Position
    final_speed: FinalSpeed | None
    tolerance_master: float  # [m] (1.1+; 0 when not written)
    tolerance: float  # [m]


@dataclass(frozen=True, slots=True)
class LateralDistanceAction:
    """Keep a lateral distance to `entity` (None: the entity's lateral place, 0 m)."""

    entity: str
    distance: float | None  # [m]
    freespace: bool  # between bounding boxes (True) or reference points (False)
    continuous: bool
    coordinate_system: str  # entity, lane, road, trajectory (1.1+; default entity)
    displacement: str  # any, leftToReferencedEntity, rightToReferencedEntity (1.1+)
    constraints: DynamicConstraints | None  # max_acceleration, max_speed: lateral


@dataclass(frozen=True, slots=True)
class SpeedProfileEntry:
    speed: float  # [m/s] (plus the entity's speed when the action names one)
    time: float | None  # [s] to reach it after the previous entry; None: at the limits


@dataclass(frozen=True, slots=True)
class SpeedProfileAction:
    """Speeds to reach one after the other (1.2)."""

    entity: str | None  # speeds relative to this entity's speed when the action starts
    following_mode: FollowingMode
    entries: tuple[SpeedProfileEntry, ...]
    constraints: DynamicConstraints | None


@dataclass(frozen=True, slots=True)
class AbsoluteTargetLane:
    value: str  # OpenDRIVE lane id


@dataclass(frozen=True, slots=True)
class RelativeTargetLane:
    entity: str
    value: int  # lanes to the left (positive) of the entity's lane


@dataclass(frozen=True, slots=True)
class LaneChangeAction:
    dynamics: TransitionDynamics  # rate: lateral speed [m/s]
    target: AbsoluteTargetLane | RelativeTargetLane
    target_lane_offset: float | None  # [m] in the target lane, None = 0


@dataclass(frozen=True, slots=True)
class AbsoluteTargetLaneOffset:
    value: float  # [m] from the current lane's centre, left positive


@dataclass(frozen=True, slots=True)
class RelativeTargetLaneOffset:
    entity: str
    value: float  # [m] relative to the entity's lane offset


@dataclass(frozen=True, slots=True)
class LaneOffsetDynamics:
    max_lateral_acc: float | None  # [m/s²]
    shape: DynamicsShape


@dataclass(frozen=True, slots=True)
class LaneOffsetAction:
    continuous: bool
    dynamics: LaneOffsetDynamics
    target: AbsoluteTargetLaneOffset | RelativeTargetLaneOffset


@dataclass(frozen=True, slots=True)
class Timing:
    domain: Literal["absolute", "relative"]  # vertex times: simulation time or since start
    scale: float  # [-] vertex time multiplier
    offset: float  # [s] added after scaling


@dataclass(frozen=True, slots=True)
class FollowTrajectoryAction:
    trajectory: Trajectory
    time_reference: Timing | None  # None: vertex times are ignored
    following_mode: FollowingMode
    initial_distance_offset: float | None  # [m] along the trajectory (1.1+)


@dataclass(frozen=True, slots=True)
class ActivateControllerAction:
    lateral: bool | None  # None: unchanged
    longitudinal: bool | None
    lighting: bool | None  # 1.2
    animation: bool | None  # 1.2


@dataclass(frozen=True, slots=True)
class AssignControllerAction:
    controller: Controller
    activate_lateral: bool | None  # 1.1+ attributes; None when not written
    activate_longitudinal: bool | None
    activate_lighting: bool | None  # 1.2
    activate_animation: bool | None  # 1.2


@dataclass(frozen=True, slots=True)
class PedalOverride:
    """One pedal of an OverrideControllerValueAction: the driver's throttle or brake."""

    pedal: Literal["throttle", "brake"]
    active: bool  # False: the pedal is released (the override ends)
    value: float  # [-] 0..1, the pedal position
    max_rate: float | None  # [1/s] the pedal moves at most this fast (1.2+); None: at once


@dataclass(frozen=True, slots=True)
class OverrideControllerValueAction:
    """The driver's pedals on the car under test (`avsim.run.storyboard.driver`); the
    file's other controls (clutch, parking brake, steering wheel, gear) may only be written
    inactive."""

    pedals: tuple[PedalOverride, ...]


def engages(action: ActivateControllerAction | AssignControllerAction, now: bool) -> bool:
    """The switch of the car under test's automated driving function (`World.engaged`: on,
    avsim's stack drives it) after its controller `action`, `now` before it: on where it
    activates the lateral or longitudinal domain, off where it
    deactivates those it names; an activation that names neither turns it on, an assignment
    that names neither leaves it as it was (`now`)."""
    if isinstance(action, ActivateControllerAction):
        domains, unnamed = (action.lateral, action.longitudinal), True
    else:
        domains, unnamed = (action.activate_lateral, action.activate_longitudinal), now
    if any(domains):
        return True
    return unnamed if all(d is None for d in domains) else False


PrivateAction = (
    TeleportAction
    | SpeedAction
    | LongitudinalDistanceAction
    | SynchronizeAction
    | SpeedProfileAction
    | LateralDistanceAction
    | LaneChangeAction
    | LaneOffsetAction
    | FollowTrajectoryAction
    | ActivateControllerAction
    | AssignControllerAction
    | OverrideControllerValueAction
    | VisibilityAction
    | LightStateAction
)
