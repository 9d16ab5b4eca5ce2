"""Reading GlobalActions (EnvironmentAction, VariableAction, ParameterAction),
VariableDeclarations and the conditions on variables, time of day, acceleration, angles
and clearance: what each becomes, and the one-line refusal of each bad value."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.openscenario import load_openscenario
from avsim.scenario.openscenario.conditions import (
    AccelerationCondition,
    AngleCondition,
    ConditionKind,
    RelativeAngleCondition,
    RelativeClearanceCondition,
    TimeOfDayCondition,
    VariableCondition,
)
from avsim.scenario.openscenario.environment import (
    Environment,
    EnvironmentAction,
    Fog,
    FogBox,
    Precipitation,
    RoadCondition,
    Sun,
    TimeOfDay,
    Weather,
    Wind,
)
from avsim.scenario.openscenario.model import OpenScenario
from avsim.scenario.openscenario.variables import (
    ModifyValue,
    SetValue,
    VariableAction,
    VariableDeclaration,
)

DATA = Path(__file__).parent / "data"
MINIMAL = (DATA / "minimal.xosc").read_text()
PARAMS_END = "</ParameterDeclarations>"
INIT_PRIVATE = '<Private entityRef="Ego">'
MAIN_ACTION = MINIMAL[MINIMAL.index("<PrivateAction>\n                  <Longitudinal"):
                      MINIMAL.index("</Action>")]
AT_ONE = MINIMAL[MINIMAL.index("<ByValueCondition>\n                      <SimulationTime"):
                 MINIMAL.index("</Condition>")]
VARIABLES = ('<VariableDeclarations>'
             '<VariableDeclaration name="hit" variableType="boolean" value="false"/>'
             '<VariableDeclaration name="count" variableType="int" value="3"/>'
             '<VariableDeclaration name="speed" variableType="double" value="$Speed"/>'
             '<VariableDeclaration name="label" variableType="string" value="a"/>'
             '</VariableDeclarations>')
ENVIRONMENT = """<Environment name="Dusk">
  <TimeOfDay animation="true" dateTime="2020-02-21T18:30:00"/>
  <Weather fractionalCloudCover="threeOktas" temperature="283.15" atmosphericPressure="101325">
    <Sun illuminance="400" azimuth="4.5" elevation="0.05"/>
    <Fog visualRange="250"><BoundingBox><Center x="1" y="2" z="3"/>
      <Dimensions length="100" width="50" height="10"/></BoundingBox></Fog>
    <Precipitation precipitationType="rain" precipitationIntensity="2.5"/>
    <Wind direction="1.0" speed="6"/>
  </Weather>
  <RoadCondition frictionScaleFactor="0.7" wetness="wetWithPuddles"/>
</Environment>"""


def variant(tmp_path: Path, *swaps: tuple[str, str], minor: int = 2) -> Path:
    text = MINIMAL.replace('revMinor="1"', f'revMinor="{minor}"')
    for old, new in swaps:
        assert old in text, old
        text = text.replace(old, new, 1)
    path = tmp_path / "variant.xosc"
    path.write_text(text)
    return path


def load(tmp_path: Path, *swaps: tuple[str, str], minor: int = 2) -> OpenScenario:
    return load_openscenario(variant(tmp_path, *swaps, minor=minor))


def refusal(tmp_path: Path, *swaps: tuple[str, str]) -> str:
    path = variant(tmp_path, *swaps)
    with pytest.raises(ScenarioError) as info:
        load_openscenario(path)
    text = str(info.value)
    assert "\n" not in text and text.startswith(f"{path}: line ")
    return text


def in_init(xml: str) -> tuple[str, str]:
    return INIT_PRIVATE, f"<GlobalAction>{xml}</GlobalAction>{INIT_PRIVATE}"


def in_story(xml: str) -> tuple[str, str]:
    return MAIN_ACTION, f"<GlobalAction>{xml}</GlobalAction>"


def declared() -> tuple[str, str]:
    return PARAMS_END, PARAMS_END + VARIABLES


def test_an_inline_environment_in_init_is_read_in_si_units(tmp_path: Path) -> None:
    osc = load(tmp_path, in_init(f"<EnvironmentAction>{ENVIRONMENT}</EnvironmentAction>"))
    (action,) = osc.storyboard.init_global
    assert action == EnvironmentAction(Environment(
        name="Dusk",
        time_of_day=TimeOfDay(True, "2020-02-21T18:30:00", 1582309800.0),
        weather=Weather(
            cloud_state=None, cloud_cover="threeOktas", temperature=283.15, pressure=101325.0,
            sun=Sun(4.5, 0.05, 400.0),
            fog=Fog(250.0, FogBox((1.0, 2.0, 3.0), (100.0, 50.0, 10.0))),
            precipitation=Precipitation("rain", 2.5, None), wind=Wind(1.0, 6.0)),
        road_condition=RoadCondition(0.7, "wetWithPuddles")))
    assert [a.entity for a in osc.storyboard.init] == ["Ego"]  # the private actions remain


def test_a_1_0_environment_with_its_deprecated_attributes(tmp_path: Path) -> None:
    env = ('<EnvironmentAction><Environment name="E">'
           '<TimeOfDay animation="false" dateTime="2020-02-21T12:00:00+01:00"/>'
           '<Weather cloudState="overcast"><Sun intensity="1000" azimuth="0" elevation="1"/>'
           '<Fog visualRange="1000"/><Precipitation precipitationType="snow" intensity="0.5"/>'
           '</Weather><RoadCondition frictionScaleFactor="1.0"/></Environment>'
           '</EnvironmentAction>')
    (action,) = load(tmp_path, in_init(env), minor=0).storyboard.init_global
    assert isinstance(action, EnvironmentAction)
    e = action.environment
    assert e.time_of_day == TimeOfDay(False, "2020-02-21T12:00:00+01:00", 1582282800.0)
    assert e.weather is not None and e.weather.cloud_state == "overcast"
    assert e.weather.sun == Sun(0.0, 1.0, 1000.0)
    assert e.weather.precipitation == Precipitation("snow", None, 0.5)
    assert e.road_condition == RoadCondition(1.0, None)


def test_an_environment_from_a_catalog_with_a_parameter(tmp_path: Path) -> None:
    (tmp_path / "envs").mkdir()
    (tmp_path / "envs" / "Environments.xosc").write_text(
        '<?xml version="1.0"?><OpenSCENARIO><FileHeader revMajor="1" revMinor="2" date="x" '
        'description="" author=""/><Catalog name="Environments">'
        '<Environment name="Wet"><ParameterDeclarations>'
        '<ParameterDeclaration name="mu" parameterType="double" value="0.9"/>'
        '</ParameterDeclarations><RoadCondition frictionScaleFactor="$mu"/></Environment>'
        '</Catalog></OpenSCENARIO>')
    ref = ('<EnvironmentAction><CatalogReference catalogName="Environments" entryName="Wet">'
           '<ParameterAssignments><ParameterAssignment parameterRef="mu" value="0.4"/>'
           '</ParameterAssignments></CatalogReference></EnvironmentAction>')
    locations = ("<CatalogLocations></CatalogLocations>",
                 '<CatalogLocations><EnvironmentCatalog><Directory path="envs"/>'
                 '</EnvironmentCatalog></CatalogLocations>')
    osc = load(tmp_path, locations, in_story(ref))
    action = osc.storyboard.stories[0].acts[0].maneuver_groups[0].maneuvers[0].events[0] \
        .actions[0].private_action
    assert action == EnvironmentAction(Environment("Wet", None, None, RoadCondition(0.4, None)))


def test_variables_are_declared_typed_and_may_use_parameters(tmp_path: Path) -> None:
    osc = load(tmp_path, declared())
    assert osc.variables == (
        VariableDeclaration("hit", "boolean", False), VariableDeclaration("count", "int", 3),
        VariableDeclaration("speed", "double", 10.0), VariableDeclaration("label", "string", "a"))


@pytest.mark.parametrize(("xml", "expected"), [
    ('<VariableAction variableRef="hit"><SetAction value="true"/></VariableAction>',
     VariableAction("variable", "hit", "boolean", SetValue(True))),
    ('<VariableAction variableRef="speed"><SetAction value="${$Speed + 1}"/></VariableAction>',
     VariableAction("variable", "speed", "double", SetValue(11.0))),
    ('<VariableAction variableRef="count"><ModifyAction><Rule><AddValue value="2"/></Rule>'
     '</ModifyAction></VariableAction>',
     VariableAction("variable", "count", "int", ModifyValue("add", 2.0))),
    ('<VariableAction variableRef="speed"><ModifyAction><Rule><MultiplyByValue value="0.5"/>'
     '</Rule></ModifyAction></VariableAction>',
     VariableAction("variable", "speed", "double", ModifyValue("multiply", 0.5))),
    ('<ParameterAction parameterRef="Speed"><SetAction value="4"/></ParameterAction>',
     VariableAction("parameter", "Speed", "double", SetValue(4.0))),
    ('<ParameterAction parameterRef="Speed"><ModifyAction><Rule><AddValue value="-1"/></Rule>'
     '</ModifyAction></ParameterAction>',
     VariableAction("parameter", "Speed", "double", ModifyValue("add", -1.0))),
])
def test_variable_and_parameter_actions(tmp_path: Path, xml: str,
                                        expected: VariableAction) -> None:
    osc = load(tmp_path, declared(), in_story(xml))
    (_, action), = osc.storyboard.story_actions()
    assert action.private_action == expected
    assert load(tmp_path, declared(), in_init(xml)).storyboard.init_global == (expected,)


ENTITY = ('<ByEntityCondition><TriggeringEntities triggeringEntitiesRule="any">'
          '<EntityRef entityRef="Ego"/></TriggeringEntities><EntityCondition>{}'
          '</EntityCondition></ByEntityCondition>')
VALUE = "<ByValueCondition>{}</ByValueCondition>"


@pytest.mark.parametrize(("xml", "expected"), [
    (VALUE.format('<VariableCondition variableRef="hit" rule="equalTo" value="true"/>'),
     VariableCondition("hit", "true", "equalTo")),
    (VALUE.format('<TimeOfDayCondition dateTime="2020-02-21T18:31:00" rule="greaterThan"/>'),
     TimeOfDayCondition("2020-02-21T18:31:00", 1582309860.0, "greaterThan")),
    (ENTITY.format('<AccelerationCondition value="-3" rule="lessThan"/>'),
     AccelerationCondition(-3.0, "lessThan", None)),
    (ENTITY.format('<AccelerationCondition value="2" rule="greaterThan" direction="lateral"/>'),
     AccelerationCondition(2.0, "greaterThan", "lateral")),
    (ENTITY.format('<AngleCondition angleType="heading" angle="0.5" angleTolerance="0.1"/>'),
     AngleCondition("heading", 0.5, 0.1, "world")),
    (ENTITY.format('<AngleCondition angleType="roll" angle="0" angleTolerance="0.1" '
                   'coordinateSystem="lane"/>'),
     AngleCondition("roll", 0.0, 0.1, "lane")),
    (ENTITY.format('<RelativeAngleCondition entityRef="Ego" angleType="heading" angle="-1" '
                   'angleTolerance="0.2"/>'),
     RelativeAngleCondition("Ego", "heading", -1.0, 0.2, "entity")),
    (ENTITY.format('<RelativeClearanceCondition oppositeLanes="false" freeSpace="true" '
                   'distanceForward="50" distanceBackward="10"><RelativeLaneRange from="1" '
                   'to="1"/><RelativeLaneRange to="-1"/><EntityRef entityRef="Ego"/>'
                   '</RelativeClearanceCondition>'),
     RelativeClearanceCondition(("Ego",), 50.0, 10.0, True, False, ((1, 1), (None, -1)))),
    (ENTITY.format('<RelativeClearanceCondition oppositeLanes="true" freeSpace="false"/>'),
     RelativeClearanceCondition((), 0.0, 0.0, False, True, ())),
])
def test_conditions(tmp_path: Path, xml: str, expected: ConditionKind) -> None:
    osc = load(tmp_path, declared(), (AT_ONE, xml))
    event = osc.storyboard.stories[0].acts[0].maneuver_groups[0].maneuvers[0].events[0]
    assert event.start_trigger is not None
    assert event.start_trigger.groups[0].conditions[0].kind == expected


@pytest.mark.parametrize(("swap", "problem"), [
    (in_init('<EnvironmentAction><Environment name="E"><RoadCondition frictionScaleFactor='
             '"-0.1"/></Environment></EnvironmentAction>'),
     r"RoadCondition: frictionScaleFactor: must be in \[0, 10\] \[-\], got -0.1"),
    (in_init('<EnvironmentAction><Environment name="E"><TimeOfDay animation="false" '
             'dateTime="noon"/></Environment></EnvironmentAction>'),
     "TimeOfDay: dateTime: not an ISO 8601 date and time: 'noon'"),
    (in_init('<EnvironmentAction><Environment name="E"><Weather><Sun azimuth="7" '
             'elevation="0"/></Weather></Environment></EnvironmentAction>'),
     r"Sun: azimuth: must be in \[0, 6.28319\] rad, got 7"),
    (in_init('<EnvironmentAction><Environment name="E"><Weather><Fog visualRange="NaN"/>'
             '</Weather></Environment></EnvironmentAction>'),
     "Fog: visualRange: expected a finite number, got 'NaN'"),
    (in_init('<EnvironmentAction><Environment name="E"><Weather temperature="500"/>'
             '</Environment></EnvironmentAction>'),
     r"Weather: temperature: must be in \[170, 340\] K, got 500"),
    (in_init('<EnvironmentAction><Environment name="E"><Weather><DomeImage/></Weather>'
             '</Environment></EnvironmentAction>'),
     r"DomeImage: not supported yet \(DomeImage\)"),
    (in_init('<EnvironmentAction><Environment name="E"><Weather><Precipitation '
             'precipitationType="hail"/></Weather></Environment></EnvironmentAction>'),
     "Precipitation: precipitationType: 'hail' is not one of dry, rain, snow"),
    (in_init('<VariableAction variableRef="nope"><SetAction value="1"/></VariableAction>'),
     r"VariableAction: variableRef: no variable nope \(variables: count, hit, label, speed\)"),
    (in_init('<VariableAction variableRef="count"><SetAction value="x"/></VariableAction>'),
     "SetAction: value: expected an integer, got 'x'"),
    (in_init('<VariableAction variableRef="label"><ModifyAction><Rule><AddValue value="1"/>'
             '</Rule></ModifyAction></VariableAction>'),
     "ModifyAction: label is a string: only a number can be modified"),
    (in_init('<ParameterAction parameterRef="Nope"><SetAction value="1"/></ParameterAction>'),
     "ParameterAction: parameterRef: no parameter Nope"),
    (in_init("<TrafficAction/>"), r"TrafficAction: not supported yet \(TrafficAction\)"),
    ((AT_ONE, VALUE.format('<VariableCondition variableRef="x" rule="equalTo" value="1"/>')),
     r"VariableCondition: variableRef: no variable x \(variables: count, hit, label, speed\)"),
    ((AT_ONE, ENTITY.format('<AngleCondition angleType="heading" angle="0" angleTolerance="1" '
                            'coordinateSystem="trajectory"/>')),
     r"AngleCondition: not supported yet \(coordinateSystem trajectory\)"),
    ((AT_ONE, ENTITY.format('<AngleCondition angleType="yaw" angle="0" angleTolerance="1"/>')),
     "AngleCondition: angleType: 'yaw' is not one of heading, pitch, roll"),
    ((AT_ONE, ENTITY.format('<RelativeClearanceCondition oppositeLanes="false" '
                            'freeSpace="false"><RelativeLaneRange from="2" to="1"/>'
                            '</RelativeClearanceCondition>')),
     r"RelativeLaneRange: from \(2\) is greater than to \(1\)"),
    ((AT_ONE, ENTITY.format('<RelativeClearanceCondition oppositeLanes="false" '
                            'freeSpace="false" distanceForward="-5"/>')),
     r"RelativeClearanceCondition: distanceForward: must be in \[0, 10000\] m, got -5"),
    ((AT_ONE, ENTITY.format('<AccelerationCondition value="1e9" rule="lessThan"/>')),
     r"AccelerationCondition: value: must be in \[-100, 100\] m/s², got 1000000000"),
])
def test_bad_values_are_refused_on_one_line(tmp_path: Path, swap: tuple[str, str],
                                            problem: str) -> None:
    text = refusal(tmp_path, declared(), swap)
    assert re.search(problem + "$", text), text


def test_variables_declared_twice_are_refused(tmp_path: Path) -> None:
    twice = VARIABLES.replace('name="count"', 'name="hit"')
    text = refusal(tmp_path, (PARAMS_END, PARAMS_END + twice))
    assert text.endswith("VariableDeclaration[hit]: variable hit declared twice"), text


def test_angles_may_be_a_full_turn(tmp_path: Path) -> None:
    xml = ENTITY.format(f'<AngleCondition angleType="heading" angle="{-2 * math.pi:.6f}" '
                        'angleTolerance="0"/>')
    osc = load(tmp_path, (AT_ONE, xml))
    event = osc.storyboard.stories[0].acts[0].maneuver_groups[0].maneuvers[0].events[0]
    assert event.start_trigger is not None
    kind = event.start_trigger.groups[0].conditions[0].kind
    assert isinstance(kind, AngleCondition) and kind.angle == pytest.approx(-2 * math.pi)
