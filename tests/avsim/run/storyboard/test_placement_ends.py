"""A LongitudinalDistanceAction that places its actor at once (not continuous, no
acceleration limits) ends in the trigger check it starts, as esmini places the actor and
ends the action in the same step: an event waiting on its maneuver's end starts at the next
check (Euro NCAP CCRb's GVT brakes 3 s after its placement: at 3.025 s, not 3.05 s).
A short run on a real world, car under test scripted, no sensors."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from avsim.run.runner import Runner
from avsim.scenario.load import load_scenario

DATA = Path(__file__).parent / "data"
CHECK = 0.025  # [s] between two trigger checks


def _vehicle(name: str) -> str:
    return f"""<ScenarioObject name="{name}"><Vehicle name="{name}_car" vehicleCategory="car">
      <BoundingBox><Center x="1.3" y="0" z="0.75"/><Dimensions width="1.8" length="4.5"
        height="1.5"/></BoundingBox>
      <Performance maxSpeed="70" maxAcceleration="5" maxDeceleration="10"/>
      <Axles><FrontAxle maxSteering="0.5" wheelDiameter="0.6" trackWidth="1.6" positionX="2.8"
        positionZ="0.3"/><RearAxle maxSteering="0" wheelDiameter="0.6" trackWidth="1.6"
        positionX="0" positionZ="0.3"/></Axles><Properties/></Vehicle></ScenarioObject>"""


def _init(name: str, s: float) -> str:
    return f"""<Private entityRef="{name}">
      <PrivateAction><TeleportAction><Position><LanePosition roadId="0" laneId="-1"
        s="{s}" offset="0"/></Position></TeleportAction></PrivateAction>
      <PrivateAction><LongitudinalAction><SpeedAction>
        <SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
        <SpeedActionTarget><AbsoluteTargetSpeed value="10"/></SpeedActionTarget>
      </SpeedAction></LongitudinalAction></PrivateAction></Private>"""


GROUP = """<ManeuverGroup maximumExecutionCount="1" name="GvtGroup">
  <Actors selectTriggeringEntities="false"><EntityRef entityRef="GVT"/></Actors>
  <Maneuver name="Place"><Event name="PlaceEvent" priority="override">
    <Action name="PlaceAction"><PrivateAction><LongitudinalAction>
      <LongitudinalDistanceAction freespace="true" continuous="false" entityRef="Ego"
        distance="12" displacement="leadingReferencedEntity" coordinateSystem="entity"/>
    </LongitudinalAction></PrivateAction></Action></Event></Maneuver>
  <Maneuver name="Brake"><Event name="BrakeEvent" priority="override">
    <Action name="BrakeAction"><PrivateAction><LongitudinalAction><SpeedAction>
      <SpeedActionDynamics dynamicsShape="linear" dynamicsDimension="rate" value="2"/>
      <SpeedActionTarget><AbsoluteTargetSpeed value="0"/></SpeedActionTarget>
    </SpeedAction></LongitudinalAction></PrivateAction></Action>
    <StartTrigger><ConditionGroup><Condition name="Placed" delay="0" conditionEdge="none">
      <ByValueCondition><StoryboardElementStateCondition storyboardElementType="maneuver"
        storyboardElementRef="Place" state="completeState"/></ByValueCondition>
    </Condition></ConditionGroup></StartTrigger></Event></Maneuver></ManeuverGroup>"""


@pytest.fixture(scope="module")
def history(tmp_path_factory: pytest.TempPathFactory) -> list[tuple[float, str, str, str]]:
    folder = tmp_path_factory.mktemp("placement")
    text = (DATA / "motion_actions.xosc").read_text()
    text = text.replace("ENTITIES", _vehicle("Ego") + _vehicle("GVT"))
    text = text.replace("INIT", _init("Ego", 20.0) + _init("GVT", 100.0))
    text = text.replace("GROUPS", GROUP)
    shutil.copy(DATA / "straight.xodr", folder / "straight.xodr")
    path = folder / "placement.xosc"
    path.write_text(text)
    runner = Runner(load_scenario(path, {"duration": 0.2}, scripted_ego=True), profile=None)
    result = runner.run()
    assert result.error is None, result.error
    assert runner.director is not None
    return runner.director.runtime.history()


def _at(history: list[tuple[float, str, str, str]], kind: str, name: str,
        transition: str) -> float:
    return next(t for t, k, n, x in history if (k, n, x) == (kind, name, transition))


def test_the_placement_ends_in_the_check_it_starts(
        history: list[tuple[float, str, str, str]]) -> None:
    assert _at(history, "action", "PlaceAction", "startTransition") == 0.0
    assert _at(history, "action", "PlaceAction", "endTransition") == 0.0
    assert _at(history, "maneuver", "Place", "endTransition") == 0.0


def test_an_event_on_its_end_starts_at_the_next_check(
        history: list[tuple[float, str, str, str]]) -> None:
    assert _at(history, "event", "BrakeEvent", "startTransition") == pytest.approx(CHECK)
