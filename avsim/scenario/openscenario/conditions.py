"""Triggers and conditions (OpenSCENARIO's Trigger, ConditionGroup, Condition and the
ByEntity/ByValue condition choices). Values in SI units."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from avsim.scenario.openscenario.positions import Position

Rule = Literal["greaterThan", "lessThan", "equalTo", "greaterOrEqual", "lessOrEqual", "notEqualTo"]
Edge = Literal["none", "rising", "falling", "risingOrFalling"]
RelativeDistanceType = Literal["longitudinal", "lateral", "cartesianDistance", "euclidianDistance"]
CoordinateSystem = Literal["entity", "lane", "road", "trajectory"]
AngleCoordinates = Literal["entity", "lane", "road", "world"]  # 1.3 (trajectory refused)
AngleType = Literal["heading", "pitch", "roll"]
Direction = Literal["longitudinal", "lateral", "vertical"]


@dataclass(frozen=True, slots=True)
class SimulationTimeCondition:
    value: float  # [s]
    rule: Rule


@dataclass(frozen=True, slots=True)
class StoryboardElementStateCondition:
    element_type: str  # story, act, maneuver, event, action, maneuverGroup
    element_ref: str  # the element's name
    state: str  # startTransition, endTransition, stopTransition, skipTransition,
    # completeState, runningState, standbyState


@dataclass(frozen=True, slots=True)
class ParameterCondition:
    parameter: str
    value: str  # as written, compared with the parameter's value
    rule: Rule


@dataclass(frozen=True, slots=True)
class VariableCondition:
    variable: str
    value: str  # as written, compared with the variable's value read as its type
    rule: Rule


@dataclass(frozen=True, slots=True)
class TimeOfDayCondition:
    date_time: str  # ISO 8601 as written
    epoch: float  # [s] since 1970-01-01T00:00:00 UTC (no zone written: UTC)
    rule: Rule


@dataclass(frozen=True, slots=True)
class AccelerationCondition:
    value: float  # [m/s²]
    rule: Rule
    direction: Direction | None  # 1.2; None: the magnitude, signed as the longitudinal part


@dataclass(frozen=True, slots=True)
class AngleCondition:
    """The triggering entity's angle in a coordinate system is `angle` within `tolerance`."""

    angle_type: AngleType
    angle: float  # [rad]
    tolerance: float  # [rad]
    coordinate_system: AngleCoordinates  # default world


@dataclass(frozen=True, slots=True)
class RelativeAngleCondition:
    """The triggering entity's angle relative to `entity`'s is `angle` within `tolerance`."""

    entity: str
    angle_type: AngleType
    angle: float  # [rad]
    tolerance: float  # [rad]
    coordinate_system: AngleCoordinates  # default entity


@dataclass(frozen=True, slots=True)
class RelativeClearanceCondition:
    """No entity (of `entities`, or any other when empty) in the lanes `lane_ranges` relative
    to the triggering entity's (left +, in its driving direction) between `distance_backward`
    behind and `distance_forward` ahead of it, and such a lane exists where it is."""

    entities: tuple[str, ...]
    distance_forward: float  # [m] default 0
    distance_backward: float  # [m] default 0
    freespace: bool
    opposite_lanes: bool  # lanes of the other driving direction count
    lane_ranges: tuple[tuple[int | None, int | None], ...]  # (from, to); None: unbounded


@dataclass(frozen=True, slots=True)
class RelativeDistanceCondition:
    entity: str
    distance_type: RelativeDistanceType
    value: float  # [m]
    freespace: bool
    rule: Rule
    coordinate_system: CoordinateSystem  # default entity


@dataclass(frozen=True, slots=True)
class DistanceCondition:
    position: Position
    value: float  # [m]
    freespace: bool
    rule: Rule
    distance_type: RelativeDistanceType  # 1.1+ (default euclidianDistance)
    coordinate_system: CoordinateSystem


@dataclass(frozen=True, slots=True)
class TimeHeadwayCondition:
    entity: str
    value: float  # [s]
    freespace: bool
    rule: Rule
    coordinate_system: CoordinateSystem
    distance_type: RelativeDistanceType


@dataclass(frozen=True, slots=True)
class TimeToCollisionCondition:
    """Time to collision with an entity or a position (one of the two is set)."""

    entity: str | None
    position: Position | None
    value: float  # [s]
    freespace: bool
    rule: Rule
    coordinate_system: CoordinateSystem
    distance_type: RelativeDistanceType


@dataclass(frozen=True, slots=True)
class ReachPositionCondition:
    position: Position
    tolerance: float  # [m]


@dataclass(frozen=True, slots=True)
class TraveledDistanceCondition:
    value: float  # [m]


@dataclass(frozen=True, slots=True)
class SpeedCondition:
    value: float  # [m/s]
    rule: Rule


@dataclass(frozen=True, slots=True)
class RelativeSpeedCondition:
    entity: str
    value: float  # [m/s] triggering entity's speed minus the entity's
    rule: Rule


@dataclass(frozen=True, slots=True)
class StandStillCondition:
    duration: float  # [s]


@dataclass(frozen=True, slots=True)
class EndOfRoadCondition:
    duration: float  # [s]


@dataclass(frozen=True, slots=True)
class OffroadCondition:
    duration: float  # [s]


@dataclass(frozen=True, slots=True)
class CollisionCondition:
    """A collision with the entity `entity`, or with any object of type `by_type` (vehicle,
    pedestrian, miscellaneous, external); exactly one is set."""

    entity: str | None
    by_type: str | None


ConditionKind = (
    SimulationTimeCondition
    | StoryboardElementStateCondition
    | ParameterCondition
    | RelativeDistanceCondition
    | DistanceCondition
    | TimeHeadwayCondition
    | TimeToCollisionCondition
    | ReachPositionCondition
    | TraveledDistanceCondition
    | SpeedCondition
    | RelativeSpeedCondition
    | StandStillCondition
    | EndOfRoadCondition
    | OffroadCondition
    | CollisionCondition
    | VariableCondition
    | TimeOfDayCondition
    | AccelerationCondition
    | AngleCondition
    | RelativeAngleCondition
    | RelativeClearanceCondition
)
ENTITY_CONDITIONS = (
    RelativeDistanceCondition,
    DistanceCondition,
    TimeHeadwayCondition,
    TimeToCollisionCondition,
    ReachPositionCondition,
    TraveledDistanceCondition,
    SpeedCondition,
    RelativeSpeedCondition,
    StandStillCondition,
    EndOfRoadCondition,
    OffroadCondition,
    CollisionCondition,
    AccelerationCondition,
    AngleCondition,
    RelativeAngleCondition,
    RelativeClearanceCondition,
)  # the kinds that come in a ByEntityCondition (with triggering entities)


@dataclass(frozen=True, slots=True)
class TriggeringEntities:
    rule: Literal["any", "all"]
    entities: tuple[str, ...]


@dataclass(frozen=True, slots=True)
class Condition:
    name: str
    delay: float  # [s] the condition's result is passed on this much later
    edge: Edge
    triggering_entities: TriggeringEntities | None  # None for a ByValueCondition
    kind: ConditionKind


@dataclass(frozen=True, slots=True)
class ConditionGroup:
    conditions: tuple[Condition, ...]  # all must hold (AND)


@dataclass(frozen=True, slots=True)
class Trigger:
    groups: tuple[ConditionGroup, ...]  # any group (OR); () never fires
