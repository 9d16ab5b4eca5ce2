"""A 1.2 file using every supported element, with catalogs of vehicles, controllers,
maneuvers and trajectories (with parameter assignments)."""

from __future__ import annotations

from pathlib import Path

import pytest

from avsim.scenario.openscenario import load_openscenario
from avsim.scenario.openscenario.model import (
    AbsoluteTargetLane,
    AbsoluteTargetSpeed,
    ActivateControllerAction,
    AssignControllerAction,
    CollisionCondition,
    Controller,
    DistanceCondition,
    DynamicConstraints,
    EndOfRoadCondition,
    FollowTrajectoryAction,
    LaneChangeAction,
    LaneOffsetAction,
    LanePosition,
    LongitudinalDistanceAction,
    MiscObject,
    OffroadCondition,
    OpenScenario,
    Orientation,
    ParameterCondition,
    Pedestrian,
    Polyline,
    ReachPositionCondition,
    RelativeDistanceCondition,
    RelativeLanePosition,
    RelativeObjectPosition,
    RelativeRoadPosition,
    RelativeSpeedCondition,
    RelativeTargetLaneOffset,
    RelativeTargetSpeed,
    RelativeWorldPosition,
    RoadPosition,
    SpeedAction,
    SpeedCondition,
    StandStillCondition,
    StoryboardElementStateCondition,
    TeleportAction,
    TimeToCollisionCondition,
    TransitionDynamics,
    TraveledDistanceCondition,
    Vehicle,
    WorldPosition,
)

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def scenario() -> OpenScenario:
    return load_openscenario(DATA / "everything_1_2.xosc")


def test_parameter_types(scenario: OpenScenario) -> None:
    assert scenario.rev_minor == 2
    assert scenario.parameters == {
        "Lanes": 3,
        "Count": 6,
        "Short": 65535,
        "Wet": True,
        "When": "2024-06-01T12:00:00",
        "Name": "ego",
        "Gap": 20.0,
    }
    assert scenario.road_network is None


def test_entities(scenario: OpenScenario) -> None:
    ego, walker, cone = scenario.entities
    assert isinstance(ego.object, Vehicle) and ego.object.category == "truck"
    assert ego.controller == Controller("driver", {"mode": "sporty"})
    assert isinstance(walker.object, Pedestrian) and walker.object.model == "old_style"
    assert isinstance(cone.object, MiscObject) and cone.object.model == "cone.osgb"
    assert cone.object.mass == 2.0 and cone.object.bbox.height == 0.5


def test_init_positions(scenario: OpenScenario) -> None:
    actions = [(a.entity, a.action) for a in scenario.storyboard.init]
    assert actions == [
        ("Ego", TeleportAction(RoadPosition("1", 10.0, -1.75, Orientation(0.1, 0, 0, "relative")))),
        ("Ego", ActivateControllerAction(None, True, None, None)),
        ("Walker", TeleportAction(RelativeObjectPosition("Ego", 30.0, -3.0, None, None))),
        ("Cone", TeleportAction(RelativeWorldPosition("Ego", 50.0, 0.0, 0.0, None))),
        ("Cone", TeleportAction(RelativeRoadPosition("Ego", 60.0, 1.0, None))),
        ("Cone", TeleportAction(RelativeLanePosition("Ego", 1, None, 70.0, 0.0, None))),
    ]


def test_catalog_maneuver_with_assignment(scenario: OpenScenario) -> None:
    group = scenario.storyboard.stories[0].acts[0].maneuver_groups[0]
    assert group.actors.select_triggering_entities
    (maneuver,) = group.maneuvers
    assert maneuver.name == "brake"
    (event,) = maneuver.events
    assert event.priority == "override" and event.maximum_execution_count == 2
    assert event.start_trigger is None
    action = event.actions[0].private_action
    assert action == SpeedAction(
        TransitionDynamics("linear", "rate", -5.0, None), AbsoluteTargetSpeed(0.0)
    )


def test_inline_actions(scenario: OpenScenario) -> None:
    group = scenario.storyboard.stories[0].acts[0].maneuver_groups[1]
    assert group.maximum_execution_count == 3
    event = group.maneuvers[0].events[0]
    actions = {a.name: a.private_action for a in event.actions}
    assert actions["Change"] == LaneChangeAction(
        TransitionDynamics("cubic", "distance", 50.0, "follow"), AbsoluteTargetLane("-2"), 0.3
    )
    offset = actions["Offset"]
    assert isinstance(offset, LaneOffsetAction) and offset.continuous
    assert offset.target == RelativeTargetLaneOffset("Walker", -0.5)
    assert offset.dynamics.max_lateral_acc is None and offset.dynamics.shape == "step"
    assert actions["Keep"] == LongitudinalDistanceAction(
        entity="Walker",
        distance=20.0,
        time_gap=None,
        freespace=False,
        continuous=True,
        coordinate_system="entity",
        displacement="any",
        constraints=DynamicConstraints(2.0, 4.0, 30.0, None, None),
    )
    follow = actions["Follow"]
    assert isinstance(follow, FollowTrajectoryAction)
    assert follow.time_reference is None and follow.following_mode == "follow"
    assert follow.initial_distance_offset == 2.0
    assert follow.trajectory.name == "diagonal" and follow.trajectory.parameters == {"End": 20.0}
    assert isinstance(follow.trajectory.shape, Polyline)
    last = follow.trajectory.shape.vertices[-1]
    assert last.time is None
    assert last.position == WorldPosition(20.0, 20.0, 0.5, 0.785, None, None)
    assign = actions["Assign"]
    assert assign == AssignControllerAction(
        Controller("inline_controller", {"k": "ego"}), False, None, None, None
    )
    assert actions["Relative"] == SpeedAction(
        TransitionDynamics("sinusoidal", "time", 4.0, None),
        RelativeTargetSpeed("Walker", 1.5, "factor", True),
    )


def test_conditions(scenario: OpenScenario) -> None:
    act = scenario.storyboard.stories[0].acts[0]
    trigger = act.maneuver_groups[1].maneuvers[0].events[0].start_trigger
    assert trigger is not None
    first, second = trigger.groups
    ttc, fast = first.conditions
    assert ttc.delay == 0.5 and ttc.edge == "falling"
    assert ttc.triggering_entities is not None
    assert ttc.triggering_entities.rule == "all"
    assert ttc.triggering_entities.entities == ("Ego", "Walker")
    assert ttc.kind == TimeToCollisionCondition(
        None,
        WorldPosition(100.0, 5.0, None, None, None, None),
        2.5,
        True,
        "lessThan",
        "lane",
        "longitudinal",
    )
    assert fast.kind == SpeedCondition(10.0, "greaterOrEqual")
    assert fast.edge == "risingOrFalling"
    kinds = {c.name: c.kind for c in second.conditions}
    assert kinds == {
        "Near": DistanceCondition(
            LanePosition("1", "-1", 200.0, 0.0, None),
            5.0,
            False,
            "lessThan",
            "euclidianDistance",
            "road",
        ),
        "Reach": ReachPositionCondition(WorldPosition(1.0, 2.0, 3.0, 0.0, 0.0, 0.0), 1.5),
        "Travel": TraveledDistanceCondition(300.0),
        "Still": StandStillCondition(2.0),
        "RoadEnd": EndOfRoadCondition(1.0),
        "Offroad": OffroadCondition(0.5),
        "HitAnyPedestrian": CollisionCondition(None, "pedestrian"),
        "HitCone": CollisionCondition("Cone", None),
        "Closing": RelativeSpeedCondition("Walker", -3.0, "lessThan"),
        "Euclid": RelativeDistanceCondition(
            "Cone", "euclidianDistance", 10.0, False, "lessOrEqual", "entity"
        ),
        "Param": ParameterCondition("Wet", "true", "equalTo"),
    }
    assert act.start_trigger is not None and act.start_trigger.groups == ()
    assert act.stop_trigger is not None
    done = act.stop_trigger.groups[0].conditions[0].kind
    assert done == StoryboardElementStateCondition("event", "S::A::Inline::M::E", "endTransition")
