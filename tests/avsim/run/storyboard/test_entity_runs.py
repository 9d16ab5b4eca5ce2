"""The entity actions played on a real world (`--profile none`, the stack drives the ego
in lane -1), in one run of `data/motion_actions.xosc` filled in here: an entity no Init
places is out of the world until a story adds it; a deleted one leaves it (no body, no
contact); a VisibilityAction hides an actor from the LiDAR and the cameras (its body stays);
a LightStateAction is recorded in the result's storyboard state."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from avsim.run.runner import Runner, RunResult
from avsim.run.storyboard.state import StateChange
from avsim.scenario.load import load_scenario
from tests.avsim.run.storyboard.test_motion_runs import init_at, lane, vehicle

pytestmark = pytest.mark.slow
DATA = Path(__file__).parent / "data"
ACTORS = ("Late", "Leaver", "Ghost")


def group(name: str, body: str, at: float, kind: str = "PrivateAction") -> str:
    actors = "" if kind == "GlobalAction" else f'<EntityRef entityRef="{name}"/>'
    return f"""<ManeuverGroup maximumExecutionCount="1" name="{name}Group">
      <Actors selectTriggeringEntities="false">{actors}</Actors>
      <Maneuver name="{name}Maneuver"><Event name="{name}Event" priority="parallel">
        <Action name="{name}Action"><{kind}>{body}</{kind}></Action>
        <StartTrigger><ConditionGroup><Condition name="{name}At" delay="0"
          conditionEdge="none"><ByValueCondition><SimulationTimeCondition value="{at}"
          rule="greaterOrEqual"/></ByValueCondition></Condition></ConditionGroup>
        </StartTrigger></Event></Maneuver></ManeuverGroup>"""


def light(name: str, light_type: str, rule: str, refs: tuple[str, ...], kind: str) -> str:
    """A group that turns Ghost's `light_type` on when the entity condition `kind` holds
    for the triggering entities `refs` (rule `rule`)."""
    body = f"""<AppearanceAction><LightStateAction><LightType><VehicleLight
        vehicleLightType="{light_type}"/></LightType><LightState mode="on"/>
        </LightStateAction></AppearanceAction>"""
    text = group(name, body, 0.0).replace(f'<EntityRef entityRef="{name}"/>',
                                          '<EntityRef entityRef="Ghost"/>')
    refs_xml = "".join(f'<EntityRef entityRef="{r}"/>' for r in refs)
    by_entity = f"""<ByEntityCondition><TriggeringEntities triggeringEntitiesRule="{rule}">
        {refs_xml}</TriggeringEntities><EntityCondition>{kind}</EntityCondition>
        </ByEntityCondition>"""
    return text.replace("""<ByValueCondition><SimulationTimeCondition value="0.0"
          rule="greaterOrEqual"/></ByValueCondition>""", by_entity)


GROUPS = (
    group("Add", f"""<EntityAction entityRef="Late"><AddEntityAction><Position>
        {lane("-2", 300.0)}</Position></AddEntityAction></EntityAction>""", 2.0,
          "GlobalAction"),
    group("Delete", '<EntityAction entityRef="Leaver"><DeleteEntityAction/></EntityAction>',
          1.0, "GlobalAction"),
    group("Ghost", '<VisibilityAction graphics="true" traffic="true" sensors="false"/>', 0.0),
    group("Ghost2", """<AppearanceAction><LightStateAction transitionTime="0.2"><LightType>
        <VehicleLight vehicleLightType="indicatorLeft"/></LightType><LightState
        mode="flashing" flashingOnDuration="0.5" flashingOffDuration="0.4"><Color
        colorType="orange"/></LightState></LightStateAction></AppearanceAction>""", 0.5)
    .replace('<EntityRef entityRef="Ghost2"/>', '<EntityRef entityRef="Ghost"/>'),
    # Leaver is deleted at 1 s having travelled 10 m: its held 10 m/s must not count
    light("Far", "fogLights", "any", ("Leaver",),
          '<TraveledDistanceCondition value="15"/>'),
    # Late, standing out of the world until 2 s, is skipped: Ghost alone decides "all"
    light("Both", "highBeam", "all", ("Late", "Ghost"),
          '<SpeedCondition value="5" rule="greaterThan"/>'),
)


def scenario_file(folder: Path) -> Path:
    text = (DATA / "motion_actions.xosc").read_text()
    text = text.replace("ENTITIES", "".join(vehicle(n) for n in ("Ego", *ACTORS)))
    text = text.replace("INIT", init_at("Ego", "-1", 20.0, 10.0)
                        + init_at("Leaver", "-2", 200.0, 10.0)
                        + init_at("Ghost", "-2", 100.0, 10.0))
    text = text.replace("GROUPS", "".join(GROUPS))
    shutil.copy(DATA / "straight.xodr", folder / "straight.xodr")
    path = folder / "entities.xosc"
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[RunResult, Runner]:
    path = scenario_file(tmp_path_factory.mktemp("entities"))
    runner = Runner(load_scenario(path, {"duration": 3.0}), None, profile=None)
    return runner.run(), runner


def track(result: RunResult, name: str) -> tuple[np.ndarray, np.ndarray]:
    k = ACTORS.index(name)
    return result.log.array("t"), np.array(result.log.actor_station)[:, k]


def changes(result: RunResult, kind: str) -> list[StateChange]:
    return [c for c in result.storyboard_state if c.kind == kind]


def test_an_entity_no_init_places_enters_when_added(run: tuple[RunResult, Runner]) -> None:
    _t, s = track(run[0], "Late")
    assert s == pytest.approx(300.0, abs=1e-6)  # built there, standing: it never had a speed
    [added] = [c for c in changes(run[0], "entity") if c.name == "Late"]
    assert added.t == pytest.approx(2.0) and added.value == "added"
    world = run[1].world
    assert not world.actors.gone[0]
    x, _, z = world.actors.poses.centres[0]  # the truth at the end
    assert (x, z) == (pytest.approx(300.0, abs=1e-6), pytest.approx(0.75))


def test_a_deleted_entity_leaves_the_world(run: tuple[RunResult, Runner]) -> None:
    t, s = track(run[0], "Leaver")
    assert s[t < 0.95] == pytest.approx(200.0 + 10.0 * t[t < 0.95], abs=0.06)
    assert np.ptp(s[t > 1.05]) == 0.0  # held where it left
    world = run[1].world
    assert world.actors.gone[1]
    assert world.actors.poses.centres[1, 2] < -5.0  # the truth: below the ground
    [deleted] = [c for c in changes(run[0], "entity") if c.name == "Leaver"]
    assert deleted.t == pytest.approx(1.0) and deleted.value == "deleted"


def test_a_hidden_actor_is_out_of_the_sensors_only(run: tuple[RunResult, Runner]) -> None:
    world = run[1].world
    assert world.lidar_hidden == {2} and world.camera_hidden == {2}
    t, s = track(run[0], "Ghost")
    assert s == pytest.approx(100.0 + 10.0 * t, abs=0.06)  # still in the world, moving
    [seen] = changes(run[0], "visibility")
    assert (seen.name, seen.value) == ("Ghost", "graphics=true traffic=true sensors=false")


def test_conditions_skip_an_entity_out_of_the_world(run: tuple[RunResult, Runner]) -> None:
    """esmini's inactive entities: a deleted one never triggers (its held speed is neither
    judged nor travelled), one not yet added does not count for rule "all"."""
    lights = {c.name: c for c in changes(run[0], "light")}
    assert "Ghost.fogLights" not in lights
    assert lights["Ghost.highBeam"].t == pytest.approx(0.0)
    _t, s = track(run[0], "Late")
    assert s == pytest.approx(300.0, abs=1e-6)  # the situation: Late stands once added


def test_a_light_state_is_recorded(run: tuple[RunResult, Runner]) -> None:
    [light] = [c for c in changes(run[0], "light") if c.name == "Ghost.indicatorLeft"]
    assert light.t == pytest.approx(0.5)
    assert (light.name, light.value) == (
        "Ghost.indicatorLeft", "flashing, on 0.5 s, off 0.4 s, orange, over 0.2 s")
