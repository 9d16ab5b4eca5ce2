"""What the OpenSCENARIO reader supports, from its own dispatch tables: the registry the
coverage table in `docs/openscenario.md` is generated from (`python -m
avsim.scenario.openscenario.coverage` prints it; `tests/avsim/scenario/openscenario/
test_coverage.py` keeps the docs equal to it).

Each group is one choice of the OpenSCENARIO 1.3 schema (`OpenSCENARIO.xsd`: the elements
a `PrivateAction`, a `GlobalAction`, a `Position`, ... may hold), listed in the schema's
order. An element is read when its tag is a key of the reader's table for that choice (the
table `parse_*` dispatches on), so a new reader is in the registry by construction; every
other element of the choice is refused at load with `not supported yet (<element>)`.
`PARTLY` says what of an element read is not (yet) played as the standard says.
"""

from __future__ import annotations

from collections.abc import Collection, Iterator
from dataclasses import dataclass

from avsim.scenario.openscenario.distribution import SINGLE_DISTRIBUTIONS
from avsim.scenario.openscenario.distribution_draws import DRAWS
from avsim.scenario.openscenario.parse_actions import PRIVATE_ACTION_READERS
from avsim.scenario.openscenario.parse_conditions import (
    ENTITY_CONDITION_READERS,
    VALUE_CONDITION_READERS,
)
from avsim.scenario.openscenario.parse_entities import OBJECT_READERS
from avsim.scenario.openscenario.parse_global import GLOBAL_READERS
from avsim.scenario.openscenario.parse_positions import POSITION_READERS
from avsim.scenario.openscenario.parse_trajectories import SHAPE_READERS

# the storyboard reads an Action's GlobalAction or PrivateAction (`parse_storyboard`)
_ACTION_BODIES = ("GlobalAction", "PrivateAction")


@dataclass(frozen=True)
class Group:
    """One choice of the schema: the type that holds it, its elements in the schema's
    order, and the reader's table of the elements it reads."""

    holder: str  # the schema type whose child is one of `elements`
    elements: tuple[str, ...]  # the 1.3 schema's choice
    read: Collection[str]  # the tags the reader dispatches on


GROUPS: tuple[Group, ...] = (
    Group("Action", ("GlobalAction", "UserDefinedAction", "PrivateAction"), _ACTION_BODIES),
    Group("PrivateAction", ("LongitudinalAction", "LateralAction", "VisibilityAction",
                            "SynchronizeAction", "ActivateControllerAction",
                            "ControllerAction", "TeleportAction", "RoutingAction",
                            "AppearanceAction", "TrailerAction"), PRIVATE_ACTION_READERS),
    Group("LongitudinalAction", ("SpeedAction", "LongitudinalDistanceAction",
                                 "SpeedProfileAction"), PRIVATE_ACTION_READERS),
    Group("LateralAction", ("LaneChangeAction", "LaneOffsetAction", "LateralDistanceAction"),
          PRIVATE_ACTION_READERS),
    Group("RoutingAction", ("AssignRouteAction", "FollowTrajectoryAction",
                            "AcquirePositionAction", "RandomRouteAction"),
          PRIVATE_ACTION_READERS),
    Group("ControllerAction", ("AssignControllerAction", "OverrideControllerValueAction",
                               "ActivateControllerAction"), PRIVATE_ACTION_READERS),
    Group("AppearanceAction", ("LightStateAction", "AnimationAction"), PRIVATE_ACTION_READERS),
    Group("TrailerAction", ("ConnectTrailerAction", "DisconnectTrailerAction"),
          PRIVATE_ACTION_READERS),
    Group("GlobalAction", ("EnvironmentAction", "EntityAction", "InfrastructureAction",
                           "SetMonitorAction", "ParameterAction", "TrafficAction",
                           "VariableAction"), GLOBAL_READERS),
    Group("ByValueCondition", ("ParameterCondition", "TimeOfDayCondition",
                               "SimulationTimeCondition", "StoryboardElementStateCondition",
                               "UserDefinedValueCondition", "TrafficSignalCondition",
                               "TrafficSignalControllerCondition", "VariableCondition"),
          VALUE_CONDITION_READERS),
    Group("EntityCondition", ("EndOfRoadCondition", "CollisionCondition", "OffroadCondition",
                              "TimeHeadwayCondition", "TimeToCollisionCondition",
                              "AccelerationCondition", "StandStillCondition",
                              "SpeedCondition", "RelativeSpeedCondition",
                              "TraveledDistanceCondition", "ReachPositionCondition",
                              "DistanceCondition", "RelativeDistanceCondition",
                              "RelativeClearanceCondition", "AngleCondition",
                              "RelativeAngleCondition"), ENTITY_CONDITION_READERS),
    Group("Position", ("WorldPosition", "RelativeWorldPosition", "RelativeObjectPosition",
                       "RoadPosition", "RelativeRoadPosition", "LanePosition",
                       "RelativeLanePosition", "RoutePosition", "GeoPosition",
                       "TrajectoryPosition"), POSITION_READERS),
    Group("Shape", ("Polyline", "Clothoid", "ClothoidSpline", "Nurbs"), SHAPE_READERS),
    Group("EntityObject", ("CatalogReference", "Vehicle", "Pedestrian", "MiscObject",
                           "ExternalObjectReference"), OBJECT_READERS),
    Group("DeterministicSingleParameterDistribution", ("DistributionSet", "DistributionRange",
                                                       "UserDefinedDistribution"),
          SINGLE_DISTRIBUTIONS),
    Group("StochasticDistribution", ("ProbabilityDistributionSet", "NormalDistribution",
                                     "LogNormalDistribution", "UniformDistribution",
                                     "PoissonDistribution", "Histogram",
                                     "UserDefinedDistribution"), DRAWS),
)

# what of an element read is not played as the standard says (docs: "Coverage")
PARTLY: dict[str, str] = {
    "PrivateAction.TeleportAction": "in a story not on the car under test",
    "PrivateAction.SynchronizeAction": "on actors, not on the car under test",
    "LongitudinalAction.SpeedProfileAction": "on actors, not on the car under test; "
                                             "speeds piecewise linear (jerk limits read, "
                                             "not applied)",
    "LateralAction.LateralDistanceAction": "on actors, not on the car under test; "
                                           "`maxAcceleration` read, not applied",
    "RoutingAction.FollowTrajectoryAction": "`closed` read, not looped; on the car under "
                                            "test with `--ego scripted` only",
    "ControllerAction.AssignControllerAction": "acts by its `activate*` attributes only",
    "ControllerAction.OverrideControllerValueAction": "`Throttle`, `Brake` on the car under "
                                                      "test; the other controls only "
                                                      "inactive; `BrakeForce` not yet",
    "GlobalAction.EnvironmentAction": "rendered: darkness, fog, rain and snow for the "
                                      "cameras and the LiDAR, `frictionScaleFactor` on the "
                                      "road; no headlights, a fog box fills the world; "
                                      "`DomeImage` not yet",
    "GlobalAction.EntityAction": "not in Init, not on the car under test",
    "PrivateAction.VisibilityAction": "`traffic` recorded only; `SensorReferenceSet` not yet",
    "PrivateAction.AppearanceAction": "`LightStateAction` recorded, not drawn (actor bodies "
                                      "have no lamps); `AnimationAction` not yet",
    "AppearanceAction.LightStateAction": "recorded, not drawn (actor bodies have no lamps)",
    "EntityCondition.AngleCondition": "`coordinateSystem` trajectory not yet",
    "EntityObject.Vehicle": "`Trailer` not yet",
}


@dataclass(frozen=True)
class Row:
    """One element of the registry and what the reader does with it."""

    holder: str
    element: str
    status: str  # "yes", "partly (what)" or "not yet"


def rows() -> Iterator[Row]:
    """Every element of every group, in the schema's order."""
    for group in GROUPS:
        for element in group.elements:
            if element not in group.read:
                status = "not yet"
            else:
                note = PARTLY.get(f"{group.holder}.{element}")
                status = "yes" if note is None else f"partly: {note}"
            yield Row(group.holder, element, status)


def read_elements() -> set[str]:
    """Every tag the reader's tables dispatch on."""
    return {tag for group in GROUPS for tag in group.read}


# OpenDRIVE: what the road reader (`world.map.opendrive`) takes; details in the docs' table
OPENDRIVE: tuple[tuple[str, str], ...] = (
    ("header", "yes (revMajor 1, revMinor 4 to 8); a non-zero `offset` not yet"),
    ("road", "yes: one road, or roads linked end to end into one line"),
    ("road/link (predecessor, successor)", "yes, of `elementType` road; junctions not yet"),
    ("road/type, type/speed", "yes"),
    ("planView/geometry: line, arc, spiral, poly3, paramPoly3", "yes, exact"),
    ("elevationProfile, lateralProfile", "partly: flat only"),
    ("lanes/laneOffset", "yes"),
    ("lanes/laneSection: left, center, right, lane", "yes; lanes that begin or end between "
                                                     "sections not yet"),
    ("lane/link, lane/width, lane/speed", "yes (a lane's speed constant along it)"),
    ("lane/roadMark", "partly: `solid`, `broken`, `none`"),
    ("lane/border", "not yet"),
    ("objects/object (repeat, outline, outlines, validity)", "yes"),
    ("object markings, borders, parkingSpace, material, skeleton", "not yet"),
    ("objects/objectReference, tunnel, bridge", "not yet"),
    ("signals/signal, signalReference", "not yet (an empty `signals` is read)"),
    ("junction", "not yet"),
    ("controller, station, railroad", "not yet"),
    ("userData", "skipped wherever it appears"),
)


def markdown() -> str:
    """The generated coverage tables, as `docs/openscenario.md` holds them."""
    lines = ["| holder | element | supported |", "|---|---|---|"]
    lines += [f"| {r.holder} | `{r.element}` | {r.status} |" for r in rows()]
    lines += ["", "| OpenDRIVE element | supported |", "|---|---|"]
    lines += [f"| {element} | {status} |" for element, status in OPENDRIVE]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(markdown(), end="")
