"""The vendored ASAM/BMW ALKS OpenSCENARIO 1.1 set loads, with its values resolved."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.openscenario import declared_parameters, load_openscenario
from avsim.scenario.openscenario.model import (
    AbsoluteTargetLaneOffset,
    AbsoluteTargetSpeed,
    ActivateControllerAction,
    BoundingBox,
    FollowTrajectoryAction,
    LaneChangeAction,
    LaneOffsetAction,
    LanePosition,
    LongitudinalDistanceAction,
    OpenScenario,
    Pedestrian,
    Polyline,
    RelativeDistanceCondition,
    RelativeLanePosition,
    RelativeTargetLane,
    RelativeTargetSpeed,
    SimulationTimeCondition,
    SpeedAction,
    StoryboardElementStateCondition,
    TeleportAction,
    TimeHeadwayCondition,
    Vehicle,
)

ALKS = Path(__file__).parents[3] / "data" / "alks" / "logical_scenarios" / "concrete_scenarios"
FILES = sorted(ALKS.glob("alks_scenario_*.xosc"))
CUT_IN = ALKS / "alks_scenario_4_4_1_cut_in_no_collision_template.xosc"


def test_the_set_is_there() -> None:
    assert len(FILES) == 15


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name[14:19])
def test_every_alks_file_loads(path: Path) -> None:
    scenario = load_openscenario(path)
    assert (scenario.rev_major, scenario.rev_minor) == (1, 1)
    assert scenario.road_network is not None and scenario.road_network.is_file()
    assert scenario.entities[0].name == "Ego"
    assert scenario.storyboard.init and scenario.storyboard.stories
    assert scenario.storyboard.stop_trigger is not None


@pytest.fixture(scope="module")
def cut_in() -> OpenScenario:
    return load_openscenario(CUT_IN)


def test_cut_in_init(cut_in: OpenScenario) -> None:
    init = {(a.entity, type(a.action).__name__): a.action for a in cut_in.storyboard.init}
    ego_pos = init["Ego", "TeleportAction"]
    assert ego_pos == TeleportAction(LanePosition("0", "-4", 5.0, 0.0, None))
    ego_speed = init["Ego", "SpeedAction"]
    assert isinstance(ego_speed, SpeedAction)
    assert ego_speed.target == AbsoluteTargetSpeed(60.0 / 3.6)
    assert ego_speed.dynamics.shape == "step" and ego_speed.dynamics.value == 0.0
    teleport = init["CutInVehicle", "TeleportAction"]
    assert isinstance(teleport, TeleportAction)
    pos = teleport.position
    assert isinstance(pos, RelativeLanePosition)
    assert pos.entity == "Ego" and pos.d_lane == -1 and pos.ds_lane is None
    assert pos.ds == pytest.approx(30 + (-10 * (-20 / 3.6)))
    assert pos.ds == pytest.approx(85.5555555)
    speed = init["CutInVehicle", "SpeedAction"]
    assert isinstance(speed, SpeedAction)
    assert speed.target == RelativeTargetSpeed("Ego", -20 / 3.6, "delta", False)


def test_cut_in_story(cut_in: OpenScenario) -> None:
    activate, cut = cut_in.storyboard.stories
    assert activate.name == "ActivateALKSControllerStory" and cut.name == "CutInStory"
    act = cut.acts[0]
    assert act.name == "CutInAct"
    group = act.maneuver_groups[0]
    assert group.actors.entities == ("CutInVehicle",)
    assert not group.actors.select_triggering_entities
    event = group.maneuvers[0].events[0]
    assert event.priority == "overwrite" and event.maximum_execution_count == 1
    change = event.actions[0].private_action
    assert event.actions[0].name == "CutInAction"
    assert isinstance(change, LaneChangeAction)
    assert change.dynamics.shape == "sinusoidal"
    assert change.dynamics.dimension == "rate"
    assert change.dynamics.value == 2.0
    assert change.target == RelativeTargetLane("Ego", 0)
    accelerate = event.actions[1].private_action
    assert isinstance(accelerate, SpeedAction)
    assert accelerate.target == AbsoluteTargetSpeed(40 / 3.6)
    assert event.start_trigger is not None
    condition = event.start_trigger.groups[0].conditions[0]
    assert condition.edge == "rising"
    assert condition.triggering_entities is not None
    assert condition.triggering_entities.entities == ("Ego",)
    assert condition.kind == RelativeDistanceCondition(
        "CutInVehicle", "longitudinal", 30.0, True, "lessThan", "entity"
    )
    assert act.start_trigger is not None
    start = act.start_trigger.groups[0].conditions[0].kind
    assert start == SimulationTimeCondition(0.0, "greaterOrEqual")
    controller_action = activate.acts[0].maneuver_groups[0].maneuvers[0].events[0].actions[0]
    assert controller_action.private_action == ActivateControllerAction(True, True, None, None)


def test_cut_in_stop_trigger(cut_in: OpenScenario) -> None:
    stop = cut_in.storyboard.stop_trigger
    assert stop is not None
    (group,) = stop.groups
    (condition,) = group.conditions
    assert condition.name == "End" and condition.delay == 10.0 and condition.edge == "rising"
    assert condition.triggering_entities is None
    assert condition.kind == StoryboardElementStateCondition(
        "action", "CutInAction", "completeState"
    )


def test_cut_in_entities(cut_in: OpenScenario) -> None:
    ego = cut_in.entity("Ego")
    assert ego.controller is not None and ego.controller.name == "ALKSController"
    assert ego.controller.properties == {}
    vehicle = ego.object
    assert isinstance(vehicle, Vehicle)
    assert vehicle.name == "car_ego" and vehicle.category == "car"
    assert vehicle.bbox == BoundingBox(1.4, 0.0, 0.9, 5.0, 2.0, 1.8)
    assert (vehicle.max_speed, vehicle.max_accel, vehicle.max_decel) == (70.0, 10.0, 10.0)
    assert vehicle.front_axle.position_x == 2.98 and vehicle.front_axle.max_steering == 0.5
    assert vehicle.rear_axle.position_x == 0.0 and vehicle.rear_axle.track_width == 1.68
    assert vehicle.properties["type"] == "ego_vehicle"
    assert vehicle.properties["Mass"] == "1300.0"
    other = cut_in.entity("CutInVehicle")
    assert other.controller is None
    assert isinstance(other.object, Vehicle) and other.object.name == "car"
    assert cut_in.road_network is not None
    assert cut_in.road_network.name == "alks_road_straight.xodr"
    assert cut_in.parameters["CutInVehicle_InitPosition_RelativeLaneId"] == -1
    assert cut_in.parameters["CutInVehicle_Model"] == "car"


def test_crossing_pedestrian() -> None:
    scenario = load_openscenario(ALKS / "alks_scenario_4_2_3_crossing_pedestrian_template.xosc")
    target = scenario.entity("TargetBlocking").object
    assert isinstance(target, Pedestrian)
    assert target.mass == 70.0 and target.model == "Adult"
    assert target.bbox == BoundingBox(0.15, 0.0, 0.9, 0.3, 0.5, 1.8)
    event = scenario.storyboard.stories[1].acts[0].maneuver_groups[0].maneuvers[0].events[0]
    follow = event.actions[0].private_action
    assert isinstance(follow, FollowTrajectoryAction)
    assert follow.following_mode == "position"
    assert follow.time_reference is not None
    assert follow.time_reference.domain == "relative" and follow.time_reference.scale == 1.0
    assert isinstance(follow.trajectory.shape, Polyline)
    first, last = follow.trajectory.shape.vertices
    assert first.time == 0.0 and last.time == pytest.approx(2 * 5.0 / (5.0 / 3.6))
    assert isinstance(first.position, LanePosition) and isinstance(last.position, LanePosition)
    assert last.position.offset == -first.position.offset
    assert first.position.orientation is not None
    assert first.position.orientation.h == pytest.approx(1.57)
    assert event.start_trigger is not None
    headway = event.start_trigger.groups[0].conditions[0].kind
    assert isinstance(headway, TimeHeadwayCondition)
    assert headway.coordinate_system == "road" and headway.distance_type == "longitudinal"


def test_swerving_lead_vehicle_lane_offsets() -> None:
    scenario = load_openscenario(ALKS / "alks_scenario_4_1_2_swerving_lead_vehicle_template.xosc")
    offsets = [
        action.private_action
        for story in scenario.storyboard.stories
        for act in story.acts
        for group in act.maneuver_groups
        for maneuver in group.maneuvers
        for event in maneuver.events
        for action in event.actions
        if isinstance(action.private_action, LaneOffsetAction)
    ]
    assert len(offsets) == 4
    assert all(o.dynamics.shape == "sinusoidal" and not o.continuous for o in offsets)
    assert any(o.target == AbsoluteTargetLaneOffset(0.0) for o in offsets)
    for o in offsets:
        assert o.dynamics.max_lateral_acc is not None and o.dynamics.max_lateral_acc > 0


def test_follow_lead_vehicle_time_gap() -> None:
    path = ALKS / "alks_scenario_4_3_1_follow_lead_vehicle_comfortable_template.xosc"
    scenario = load_openscenario(path)
    gaps = [a.action for a in scenario.storyboard.init]
    distance = [a for a in gaps if isinstance(a, LongitudinalDistanceAction)]
    assert len(distance) == 1
    assert distance[0].entity == "Ego" and distance[0].distance is None
    assert distance[0].time_gap is not None and distance[0].time_gap > 0
    assert distance[0].displacement == "leadingReferencedEntity" and distance[0].freespace


def test_declared_parameters() -> None:
    infos = {i.name: i for i in declared_parameters(CUT_IN)}
    assert len(infos) == 8
    lane = infos["CutInVehicle_InitPosition_RelativeLaneId"]
    assert lane.type == "integer" and lane.default == "-1"
    assert [[c.value for c in g.constraints] for g in lane.constraint_groups] == [["-1"], ["1"]]
    assert infos["CutInVehicle_Model"].constraint_groups == ()
    speed = infos["CutInVehicle_RelativeInitSpeed_Ve0_Vo0_kph"]
    assert speed.constraint_groups[1].constraints[0].value == "${-$Ego_InitSpeed_Ve0_kph}"


def test_overrides_apply() -> None:
    scenario = load_openscenario(
        CUT_IN,
        {"CutInVehicle_InitPosition_RelativeLaneId": "1", "Ego_InitSpeed_Ve0_kph": "50"},
    )
    teleport = scenario.storyboard.init[2].action
    assert isinstance(teleport, TeleportAction)
    assert isinstance(teleport.position, RelativeLanePosition)
    assert teleport.position.d_lane == 1
    speed = scenario.storyboard.init[1].action
    assert isinstance(speed, SpeedAction)
    assert speed.target == AbsoluteTargetSpeed(50 / 3.6)
    assert scenario.parameters["Ego_InitSpeed_Ve0_kph"] == 50.0


def _message(overrides: dict[str, str]) -> str:
    with pytest.raises(ScenarioError) as info:
        load_openscenario(CUT_IN, overrides)
    text = str(info.value)
    assert "\n" not in text
    return text


def test_constraint_groups_are_ored() -> None:
    text = _message({"CutInVehicle_InitPosition_RelativeLaneId": "0"})
    assert text == (
        f"{CUT_IN}: line 19: /OpenSCENARIO/ParameterDeclarations/"
        "ParameterDeclaration[CutInVehicle_InitPosition_RelativeLaneId]: "
        "parameter CutInVehicle_InitPosition_RelativeLaneId = 0: "
        "breaks every constraint group: equalTo -1; equalTo 1"
    )


def test_constraint_refuses_too_fast_ego() -> None:
    text = _message({"Ego_InitSpeed_Ve0_kph": "70"})
    assert text == (
        f"{CUT_IN}: line 9: /OpenSCENARIO/ParameterDeclarations/"
        "ParameterDeclaration[Ego_InitSpeed_Ve0_kph]: "
        "parameter Ego_InitSpeed_Ve0_kph = 70: breaks lessOrEqual 60"
    )


def test_constraint_with_an_expression_names_it() -> None:
    text = _message({"CutInVehicle_LaneChange_MaxLateralVelocity_Vy_mps": "20"})
    assert text.endswith(
        "parameter CutInVehicle_LaneChange_MaxLateralVelocity_Vy_mps = 20: breaks lessThan "
        "11.1111 (${($Ego_InitSpeed_Ve0_kph + $CutInVehicle_RelativeInitSpeed_Ve0_Vo0_kph)"
        " / 3.6})"
    )


def test_constraint_depending_on_another_parameter() -> None:
    # +10 breaks group 1 (lessThan 0) but satisfies group 2 (greaterThan -ego speed)
    scenario = load_openscenario(CUT_IN, {"CutInVehicle_RelativeInitSpeed_Ve0_Vo0_kph": "10"})
    assert scenario.parameters["CutInVehicle_RelativeInitSpeed_Ve0_Vo0_kph"] == 10.0
    # -70 satisfies group 1 but makes the lane change's lateral speed limit negative
    text = _message({"CutInVehicle_RelativeInitSpeed_Ve0_Vo0_kph": "-70"})
    assert text.endswith(
        "parameter CutInVehicle_LaneChange_MaxLateralVelocity_Vy_mps = 2: breaks lessThan "
        "-2.77778 (${($Ego_InitSpeed_Ve0_kph + $CutInVehicle_RelativeInitSpeed_Ve0_Vo0_kph)"
        " / 3.6})"
    )


def test_unknown_override_lists_the_declared_names() -> None:
    text = _message({"nope": "1"})
    assert text.startswith(f"{CUT_IN}: (overrides): unknown parameter nope; declared: ")
    assert "Ego_InitSpeed_Ve0_kph" in text


def test_wrongly_typed_override() -> None:
    text = _message({"CutInVehicle_InitPosition_RelativeLaneId": "1.5"})
    assert text.endswith(
        "ParameterDeclaration[CutInVehicle_InitPosition_RelativeLaneId]: parameter "
        "CutInVehicle_InitPosition_RelativeLaneId (override '1.5'): expected an integer, "
        "got '1.5'"
    )
    text = _message({"Ego_InitSpeed_Ve0_kph": "fast"})
    assert text.endswith("(override 'fast'): expected a number, got 'fast'")


def test_missing_catalog_entry_names_it() -> None:
    text = _message({"CutInVehicle_Model": "hovercraft"})
    assert text.startswith(
        f"{CUT_IN}: line 84: /OpenSCENARIO/Entities/ScenarioObject[CutInVehicle]/"
        "CatalogReference: no entry hovercraft in catalog vehicle_catalog (entries: "
    )


def test_expression_results_are_finite() -> None:
    for path in FILES:
        for value in load_openscenario(path).parameters.values():
            assert not isinstance(value, float) or math.isfinite(value)
