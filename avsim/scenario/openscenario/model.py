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
    FollowTrajectoryAction,
    LaneChangeAction,
    LaneOffsetAction,
    LaneOffsetDynamics,
    LongitudinalDistanceAction,
    Polyline,
    PrivateAction,
    RelativeTargetLane,
    RelativeTargetLaneOffset,
    RelativeTargetSpeed,
    SpeedAction,
    TeleportAction,
    Timing,
    Trajectory,
    TransitionDynamics,
    Vertex,
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
    "CollisionCondition",
    "Condition",
    "ConditionGroup",
    "ConditionKind",
    "Controller",
    "DistanceCondition",
    "DynamicConstraints",
    "EndOfRoadCondition",
    "Entity",
    "Event",
    "FollowTrajectoryAction",
    "InitAction",
    "LaneChangeAction",
    "LaneOffsetAction",
    "LaneOffsetDynamics",
    "LanePosition",
    "LongitudinalDistanceAction",
    "Maneuver",
    "ManeuverGroup",
    "MiscObject",
    "OffroadCondition",
    "OpenScenario",
    "Orientation",
    "ParamValue",
    "ParameterCondition",
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
    "StandStillCondition",
    "Story",
    "Storyboard",
    "StoryboardElementStateCondition",
    "TeleportAction",
    "TimeHeadwayCondition",
    "TimeToCollisionCondition",
    "Timing",
    "Trajectory",
    "TransitionDynamics",
    "TraveledDistanceCondition",
    "Trigger",
    "TriggeringEntities",
    "Vehicle",
    "Vertex",
    "WorldPosition",
]
