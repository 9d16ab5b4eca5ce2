"""The typed model of an OpenSCENARIO file: `OpenScenario`, and every part re-exported."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from avsim.scenario.openscenario.actions import (
    AbsoluteTargetLane,
    AbsoluteTargetLaneOffset,
    AbsoluteTargetSpeed,
    ActivateControllerAction,
    AssignControllerAction,
    DynamicConstraints,
    FinalSpeed,
    FollowTrajectoryAction,
    LaneChangeAction,
    LaneOffsetAction,
    LaneOffsetDynamics,
    LateralDistanceAction,
    LongitudinalDistanceAction,
    OverrideControllerValueAction,
    PedalOverride,
    PrivateAction,
    RelativeTargetLane,
    RelativeTargetLaneOffset,
    RelativeTargetSpeed,
    SpeedAction,
    SpeedProfileAction,
    SpeedProfileEntry,
    SteadyState,
    SynchronizeAction,
    TeleportAction,
    Timing,
    TransitionDynamics,
)
from avsim.scenario.openscenario.conditions import (
    CollisionCondition,
    Condition,
    ConditionGroup,
    ConditionKind,
    DistanceCondition,
    EndOfRoadCondition,
    OffroadCondition,
    ParameterCondition,
    ReachPositionCondition,
    RelativeDistanceCondition,
    RelativeSpeedCondition,
    SimulationTimeCondition,
    SpeedCondition,
    StandStillCondition,
    StoryboardElementStateCondition,
    TimeHeadwayCondition,
    TimeToCollisionCondition,
    TraveledDistanceCondition,
    Trigger,
    TriggeringEntities,
)
from avsim.scenario.openscenario.entities import (
    Axle,
    BoundingBox,
    Controller,
    Entity,
    MiscObject,
    Pedestrian,
    Vehicle,
)
from avsim.scenario.openscenario.parameters import ParamValue
from avsim.scenario.openscenario.positions import (
    LanePosition,
    Orientation,
    Position,
    RelativeLanePosition,
    RelativeObjectPosition,
    RelativeRoadPosition,
    RelativeWorldPosition,
    RoadPosition,
    TrajectoryPosition,
    WorldPosition,
)
from avsim.scenario.openscenario.storyboard import (
    Act,
    Action,
    Actors,
    Event,
    InitAction,
    Maneuver,
    ManeuverGroup,
    Story,
    Storyboard,
)
from avsim.scenario.openscenario.trajectories import (
    Clothoid,
    ClothoidSpline,
    ClothoidSplineSegment,
    ControlPoint,
    Nurbs,
    Polyline,
    Trajectory,
    TrajectoryShape,
    Vertex,
)
from avsim.scenario.openscenario.variables import VariableDeclaration


@dataclass(frozen=True, slots=True)
class OpenScenario:
    path: Path  # the .xosc file
    rev_major: int  # 1
    rev_minor: int  # 0, 1 or 2
    description: str
    parameters: dict[str, ParamValue]  # the global parameters' values, overrides applied
    road_network: Path | None  # the OpenDRIVE LogicFile, resolved; None when not given
    entities: tuple[Entity, ...]  # in file order
    storyboard: Storyboard
    variables: tuple[VariableDeclaration, ...] = ()  # VariableDeclarations (1.2+), in order

    def entity(self, name: str) -> Entity:
        """The entity of this name (KeyError when there is none)."""
        for e in self.entities:
            if e.name == name:
                return e
        raise KeyError(name)


__all__ = [
    "AbsoluteTargetLane",
    "AbsoluteTargetLaneOffset",
    "AbsoluteTargetSpeed",
    "Act",
    "Action",
    "ActivateControllerAction",
    "Actors",
    "AssignControllerAction",
    "Axle",
    "BoundingBox",
    "Clothoid",
    "ClothoidSpline",
    "ClothoidSplineSegment",
    "CollisionCondition",
    "Condition",
    "ConditionGroup",
    "ConditionKind",
    "ControlPoint",
    "Controller",
    "DistanceCondition",
    "DynamicConstraints",
    "EndOfRoadCondition",
    "Entity",
    "Event",
    "FinalSpeed",
    "FollowTrajectoryAction",
    "InitAction",
    "LaneChangeAction",
    "LaneOffsetAction",
    "LaneOffsetDynamics",
    "LanePosition",
    "LateralDistanceAction",
    "LongitudinalDistanceAction",
    "Maneuver",
    "ManeuverGroup",
    "MiscObject",
    "Nurbs",
    "OffroadCondition",
    "OpenScenario",
    "Orientation",
    "OverrideControllerValueAction",
    "ParamValue",
    "ParameterCondition",
    "PedalOverride",
    "Pedestrian",
    "Polyline",
    "Position",
    "PrivateAction",
    "ReachPositionCondition",
    "RelativeDistanceCondition",
    "RelativeLanePosition",
    "RelativeObjectPosition",
    "RelativeRoadPosition",
    "RelativeSpeedCondition",
    "RelativeTargetLane",
    "RelativeTargetLaneOffset",
    "RelativeTargetSpeed",
    "RelativeWorldPosition",
    "RoadPosition",
    "SimulationTimeCondition",
    "SpeedAction",
    "SpeedCondition",
    "SpeedProfileAction",
    "SpeedProfileEntry",
    "StandStillCondition",
    "SteadyState",
    "Story",
    "Storyboard",
    "StoryboardElementStateCondition",
    "SynchronizeAction",
    "TeleportAction",
    "TimeHeadwayCondition",
    "TimeToCollisionCondition",
    "Timing",
    "Trajectory",
    "TrajectoryPosition",
    "TrajectoryShape",
    "TransitionDynamics",
    "TraveledDistanceCondition",
    "Trigger",
    "TriggeringEntities",
    "Vehicle",
    "Vertex",
    "WorldPosition",
]
