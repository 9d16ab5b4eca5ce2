"""Reading the entity actions: EntityAction (AddEntityAction, DeleteEntityAction),
VisibilityAction, AppearanceAction's LightStateAction; the one-line refusal of each bad
value, of AnimationAction, of a SensorReferenceSet, of an EntityAction in Init, and of an
add or delete of the car under test."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from avsim.cli import EXIT_BAD_INPUT, main
from avsim.scenario.errors import ScenarioError
from avsim.scenario.openscenario.entity_actions import (
    AddEntityAction,
    DeleteEntityAction,
    LightState,
    LightStateAction,
    VisibilityAction,
)
from avsim.scenario.openscenario.parse import load_openscenario
from avsim.scenario.openscenario.positions import WorldPosition
from tests.avsim.run.storyboard.test_entity_runs import group
from tests.avsim.run.storyboard.test_motion_runs import init_at, lane, vehicle

DATA = Path(__file__).parent / "data"
RUNS = Path(__file__).parents[3] / "avsim" / "run" / "storyboard" / "data"
MINIMAL = (DATA / "minimal.xosc").read_text()
EVENT_ACTION = re.compile(r"<PrivateAction>\s*<LongitudinalAction>.*?</LongitudinalAction>"
                          r"\s*</PrivateAction>", re.DOTALL)
LIGHT = ('<AppearanceAction><LightStateAction {attrs}><LightType>{light}</LightType>'
         '<LightState mode="{mode}" {state}>{colour}</LightState></LightStateAction>'
         '</AppearanceAction>')


def _action(tmp_path: Path, body: str) -> object:
    path = tmp_path / "s.xosc"
    path.write_text(EVENT_ACTION.sub(lambda _: body, MINIMAL, count=1))
    osc = load_openscenario(path)
    [(_, action)] = list(osc.storyboard.story_actions())
    return action.private_action


def _light(tmp_path: Path, attrs: str = "", light: str = "", mode: str = "on",
           state: str = "", colour: str = "") -> object:
    light = light or '<VehicleLight vehicleLightType="brakeLights"/>'
    return _action(tmp_path, "<PrivateAction>" + LIGHT.format(
        attrs=attrs, light=light, mode=mode, state=state, colour=colour) + "</PrivateAction>")


def test_add_and_delete_entity(tmp_path: Path) -> None:
    add = _action(tmp_path, '<GlobalAction><EntityAction entityRef="Ego"><AddEntityAction>'
                  '<Position><WorldPosition x="5" y="1" h="0"/></Position>'
                  '</AddEntityAction></EntityAction></GlobalAction>')
    assert isinstance(add, AddEntityAction) and add.entity == "Ego"
    assert add.position == WorldPosition(5.0, 1.0, None, 0.0, None, None)
    delete = _action(tmp_path, '<GlobalAction><EntityAction entityRef="Ego">'
                     '<DeleteEntityAction/></EntityAction></GlobalAction>')
    assert delete == DeleteEntityAction("Ego")


def test_visibility(tmp_path: Path) -> None:
    got = _action(tmp_path, '<PrivateAction><VisibilityAction graphics="false" '
                  'traffic="true" sensors="false"/></PrivateAction>')
    assert got == VisibilityAction(graphics=False, traffic=True, sensors=False)


def test_light_state(tmp_path: Path) -> None:
    got = _light(tmp_path, 'transitionTime="0.3"',
                 '<VehicleLight vehicleLightType="indicatorRight"/>', "flashing",
                 'luminousIntensity="50" flashingOnDuration="0.4" flashingOffDuration="0.6"',
                 '<Color colorType="orange"><ColorRgb red="1" green="0.5" blue="0"/></Color>')
    assert got == LightStateAction("indicatorRight", LightState(
        "flashing", 50.0, 0.4, 0.6, "orange", (1.0, 0.5, 0.0)), 0.3)
    user = _light(tmp_path, light='<UserDefinedLight userDefinedLightType="beacon"/>',
                  mode="off")
    assert user == LightStateAction("user:beacon", LightState(
        "off", None, None, None, None, None), 0.0)


@pytest.mark.parametrize(("body", "problem"), [
    ('<GlobalAction><EntityAction entityRef="Nobody"><DeleteEntityAction/></EntityAction>'
     '</GlobalAction>', "entityRef: no entity Nobody"),
    ('<GlobalAction><EntityAction entityRef="Ego"><AddEntityAction/></EntityAction>'
     '</GlobalAction>', "Position"),
    ('<PrivateAction><VisibilityAction graphics="maybe" traffic="true" sensors="true"/>'
     '</PrivateAction>', "graphics"),
    ('<PrivateAction><VisibilityAction graphics="true" traffic="true" sensors="false">'
     '<SensorReferenceSet><SensorReference name="front"/></SensorReferenceSet>'
     '</VisibilityAction></PrivateAction>', "not supported yet (SensorReferenceSet)"),
    ('<PrivateAction><AppearanceAction><AnimationAction/></AppearanceAction></PrivateAction>',
     "not supported yet (AnimationAction)"),
])
def test_refusals(tmp_path: Path, body: str, problem: str) -> None:
    with pytest.raises(ScenarioError, match=re.escape(problem)):
        _action(tmp_path, body)


@pytest.mark.parametrize(("kwargs", "problem"), [
    ({"light": '<VehicleLight vehicleLightType="sirens"/>'}, "vehicleLightType"),
    ({"mode": "blinking"}, "mode"),
    ({"attrs": 'transitionTime="-1"'}, "transitionTime"),
    ({"state": 'flashingOnDuration="1e999"'}, "flashingOnDuration"),
    ({"state": 'luminousIntensity="1e9"'}, "luminousIntensity"),
    ({"colour": '<Color colorType="pink"/>'}, "colorType"),
    ({"colour": '<Color colorType="red"><ColorRgb red="2" green="0" blue="0"/></Color>'},
     "red"),
    ({"colour": '<Color colorType="red"><ColorCmyk cyan="0" magenta="1" yellow="1" '
                'key="0"/></Color>'}, "not supported yet (ColorCmyk)"),
])
def test_light_refusals(tmp_path: Path, kwargs: dict[str, str], problem: str) -> None:
    with pytest.raises(ScenarioError, match=re.escape(problem)) as e:
        _light(tmp_path, **kwargs)
    assert "\n" not in str(e.value)


def test_an_entity_action_in_init_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "s.xosc"
    path.write_text(MINIMAL.replace(
        '<Private entityRef="Ego">', '<GlobalAction><EntityAction entityRef="Ego">'
        '<DeleteEntityAction/></EntityAction></GlobalAction><Private entityRef="Ego">', 1))
    with pytest.raises(ScenarioError, match="EntityAction in Init: not supported"):
        load_openscenario(path)


@pytest.mark.parametrize("inner", [
    f"<AddEntityAction><Position>{lane('-1', 50.0)}</Position></AddEntityAction>",
    "<DeleteEntityAction/>",
])
def test_cli_refuses_adding_or_deleting_the_car_under_test(tmp_path: Path, inner: str) -> None:
    """`avsim run` on a file that adds or deletes the car under test: one line on stderr,
    exit 2, nothing written."""
    text = (RUNS / "motion_actions.xosc").read_text()
    text = text.replace("ENTITIES", vehicle("Ego") + vehicle("Car"))
    text = text.replace("INIT", init_at("Ego", "-1", 20.0, 10.0) + init_at("Car", "-2", 50.0,
                                                                          10.0))
    body = f'<EntityAction entityRef="Ego">{inner}</EntityAction>'
    text = text.replace("GROUPS", group("Gone", body, 1.0, "GlobalAction"))
    shutil.copy(RUNS / "straight.xodr", tmp_path / "straight.xodr")
    path = tmp_path / "s.xosc"
    path.write_text(text)
    out = tmp_path / "out.json"
    result = CliRunner().invoke(main, ["run", str(path), "--profile", "none", "--json",
                                       str(out)])
    assert result.exit_code == EXIT_BAD_INPUT, result.output
    kind = "AddEntityAction" if "Add" in inner else "DeleteEntityAction"
    assert result.stderr.splitlines() == [
        f"avsim: error: {path}: Storyboard.Action[GoneAction]: {kind} on the car under "
        "test: not supported (the run is about it: it is always in the world)"]
    assert not out.exists()
