"""A story's actions on the car avsim's stack drives, played as its driver's inputs, one
short closed-loop run each (`--profile fast`, `avsim.run.storyboard.driver`): the ego alone
on `docs/examples/straight.xodr` at 15 m/s in the left lane (OpenDRIVE lane -1), its
function on from the start; at 2 s the story's action."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from avsim.run.runner import Runner, RunResult
from avsim.scenario.errors import ScenarioError
from avsim.scenario.load import load_scenario
from planner.messages import Motion, SpeedSource
from world.sensors.setup import Profile

pytestmark = pytest.mark.slow

EXAMPLES = Path(__file__).resolve().parents[4] / "docs" / "examples"
START = 15.0  # [m/s] the ego's Init speed (its set speed)
AT = 2.0  # [s] the action starts

TEMPLATE = """<?xml version="1.0" encoding="utf-8"?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="2" date="2026-01-01T00:00:00" author="avsim tests"
              description="an action on the car under test"/>
  <ParameterDeclarations/>
  <CatalogLocations/>
  <RoadNetwork><LogicFile filepath="straight.xodr"/></RoadNetwork>
  <Entities>
    <ScenarioObject name="Ego">
      <Vehicle name="ego_car" vehicleCategory="car">
        <BoundingBox><Center x="1.35" y="0" z="0.75"/>
          <Dimensions width="1.6" length="4.8" height="1.5"/></BoundingBox>
        <Performance maxSpeed="70" maxAcceleration="5" maxDeceleration="10"/>
        <Axles>
          <FrontAxle maxSteering="0.5" wheelDiameter="0.6" trackWidth="1.6" positionX="2.7"
                     positionZ="0.3"/>
          <RearAxle maxSteering="0" wheelDiameter="0.6" trackWidth="1.6" positionX="0"
                    positionZ="0.3"/>
        </Axles>
        <Properties/>
      </Vehicle>
    </ScenarioObject>
  </Entities>
  <Storyboard>
    <Init><Actions><Private entityRef="Ego">
      <PrivateAction><TeleportAction>
        <Position><LanePosition roadId="0" laneId="-1" offset="0" s="20"/></Position>
      </TeleportAction></PrivateAction>
      <PrivateAction><LongitudinalAction><SpeedAction>
        <SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
        <SpeedActionTarget><AbsoluteTargetSpeed value="15"/></SpeedActionTarget>
      </SpeedAction></LongitudinalAction></PrivateAction>
    </Private></Actions></Init>
    <Story name="S"><Act name="A">
      <ManeuverGroup maximumExecutionCount="1" name="G">
        <Actors selectTriggeringEntities="false"><EntityRef entityRef="Ego"/></Actors>
        <Maneuver name="M"><Event name="E" priority="overwrite">
          <Action name="DriverAction"><PrivateAction>ACTION</PrivateAction></Action>
          <StartTrigger><ConditionGroup><Condition name="At" delay="0" conditionEdge="rising">
            <ByValueCondition><SimulationTimeCondition value="2" rule="greaterOrEqual"/>
            </ByValueCondition></Condition></ConditionGroup></StartTrigger>
        </Event></Maneuver>
      </ManeuverGroup>
      <StartTrigger><ConditionGroup><Condition name="S0" delay="0" conditionEdge="none">
        <ByValueCondition><SimulationTimeCondition value="0" rule="greaterOrEqual"/>
        </ByValueCondition></Condition></ConditionGroup></StartTrigger>
    </Act></Story>
    <StopTrigger><ConditionGroup><Condition name="End" delay="DELAY" conditionEdge="rising">
      <ByValueCondition><StoryboardElementStateCondition storyboardElementType="action"
        storyboardElementRef="DriverAction" state="completeState"/></ByValueCondition>
    </Condition></ConditionGroup></StopTrigger>
  </Storyboard>
</OpenSCENARIO>
"""

SET_SPEED = """<LongitudinalAction><SpeedAction>
  <SpeedActionDynamics dynamicsShape="linear" dynamicsDimension="rate" value="5"/>
  <SpeedActionTarget><AbsoluteTargetSpeed value="10"/></SpeedActionTarget>
</SpeedAction></LongitudinalAction>"""
LANE_CHANGE = """<LateralAction><LaneChangeAction>
  <LaneChangeActionDynamics dynamicsShape="sinusoidal" dynamicsDimension="time" value="4"/>
  <LaneChangeTarget><AbsoluteTargetLane value="-2"/></LaneChangeTarget>
</LaneChangeAction></LateralAction>"""
BRAKE = """<ControllerAction><OverrideControllerValueAction>
  <Throttle active="false" value="0"/>
  <Brake active="true"><BrakePercent value="0.4"/></Brake>
  <Clutch active="false" value="0"/>
  <ParkingBrake active="false"><BrakePercent value="0"/></ParkingBrake>
  <SteeringWheel active="false" value="0"/>
  <Gear active="false"><AutomaticGear gear="d"/></Gear>
</OverrideControllerValueAction></ControllerAction>"""


def _file(tmp: Path, action: str, delay: float = 1.0) -> Path:
    """The file with `action`; the run ends `delay` [s] after the action completes."""
    shutil.copy(EXAMPLES / "straight.xodr", tmp / "straight.xodr")
    path = tmp / "driver.xosc"
    path.write_text(TEMPLATE.replace("ACTION", action).replace("DELAY", f"{delay:g}"))
    return path


def _run(tmp: Path, action: str, delay: float) -> RunResult:
    scenario = load_scenario(_file(tmp, action, delay), {"duration": 30.0})
    result = Runner(scenario, None, profile=Profile.FAST).run()
    assert result.error is None
    return result


def test_a_speed_action_sets_the_acc_s_set_speed_and_the_car_reaches_it(
        tmp_path: Path) -> None:
    result = _run(tmp_path, SET_SPEED, 11.0)
    t, v = result.log.array("t"), result.log.array("speed")
    assert t[-1] < AT + 11.0 + 0.2  # the action completed as given (the set speed set)
    target = result.log.array("target_speed")
    assert np.all(np.abs(v[(t > 1.0) & (t < AT)] - START) < 0.5)  # the Init set speed held
    assert np.all(target[t > AT + 0.2] <= 10.0 + 1e-9)  # the new set speed is the ACC's
    assert abs(v[-1] - 10.0) < 0.3  # reached, by the ACC's own law


def test_a_lane_change_action_moves_the_car_into_the_target_lane(tmp_path: Path) -> None:
    result = _run(tmp_path, LANE_CHANGE, 0.5)
    t, lane = result.log.array("t"), result.log.array("lane")
    assert np.all(lane[t < AT] == 1)  # OpenDRIVE -1: the inner lane, the left one
    assert lane[-1] == 0  # the stack's lane kept: the right one (OpenDRIVE -2)
    assert t[-1] < 20.0  # the action completed: the car's reference point in that lane
    assert Motion.LANE_CHANGE_RIGHT in result.log.motion  # by the stack's own lane change


def test_a_brake_override_slows_the_car_and_turns_the_function_off(tmp_path: Path) -> None:
    result = _run(tmp_path, BRAKE, 3.0)
    t, v = result.log.array("t"), result.log.array("speed")
    sources = result.log.speed_source
    after = [s for s, ti in zip(sources, t, strict=True) if ti > AT + 0.3]
    assert after and all(s is SpeedSource.DRIVER for s in after)  # overridden: off
    assert v[-1] < START - 0.4 * 8.0 * 1.5  # braking at about 3.2 m/s^2 for 3 s and more


def test_a_continuous_relative_speed_on_the_ego_is_refused_at_load(tmp_path: Path) -> None:
    action = SET_SPEED.replace(
        '<AbsoluteTargetSpeed value="10"/>',
        '<RelativeTargetSpeed entityRef="Ego" value="1" speedTargetValueType="delta" '
        'continuous="true"/>')
    path = _file(tmp_path, action)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert str(info.value) == (
        f"{path}: Storyboard.Action.DriverAction: SpeedAction on the car under test: a "
        "continuous relative target is not supported (its driver sets a speed once; "
        "avsim's stack drives it)")
