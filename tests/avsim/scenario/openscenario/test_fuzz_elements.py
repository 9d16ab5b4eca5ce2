"""Fuzzers of the OpenSCENARIO elements read since 1.2/1.3: parameter distribution files,
variables and their actions and conditions, environments, SynchronizeAction,
SpeedProfileAction, LateralDistanceAction, the entity actions (add, delete, visibility,
lights), the trajectory shapes (clothoid, clothoid
spline, NURBS), the driver's pedal overrides, and the elements not read yet (traffic
signals, routes, trailers). Each is generated well formed, then maybe malformed (an
attribute set to a hostile value or removed, a child removed or repeated, an element not of
the schema put in); the outcome is a loaded model or the one-line `ScenarioError`, never
another exception, and a distribution never describes more than `MAX_RUNS` runs."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from avsim.scenario.errors import ScenarioError
from avsim.scenario.openscenario.distribution import load_distribution
from avsim.scenario.openscenario.distribution_values import MAX_RUNS
from avsim.scenario.openscenario.parse import load_openscenario
from tests.fuzzing import FUZZ

pytestmark = pytest.mark.fuzz

MINIMAL = (Path(__file__).parent / "data" / "minimal.xosc").read_text()
EVENT_ACTION = re.compile(r"<PrivateAction>\s*<LongitudinalAction>.*?</LongitudinalAction>"
                          r"\s*</PrivateAction>", re.DOTALL)
EVENT_CONDITION = re.compile(r"<ByValueCondition>\s*<SimulationTimeCondition value=\"1\""
                             r"[^>]*/>\s*</ByValueCondition>", re.DOTALL)
VARIABLES = ('<VariableDeclarations><VariableDeclaration name="v" variableType="double" '
             'value="1"/><VariableDeclaration name="b" variableType="boolean" '
             'value="false"/></VariableDeclarations>')
BARE = '<WorldPosition x="{0}" y="1" h="0"/>'  # an element of type Position
POS = f"<Position>{BARE}</Position>"

ACTIONS = [  # (wrapper or "", the element) of a PrivateAction
    '<LongitudinalAction><SpeedProfileAction followingMode="follow" entityRef="Ego">'
    '<DynamicConstraints maxAcceleration="3" maxDeceleration="5" maxSpeed="30"/>'
    '<SpeedProfileEntry speed="10" time="2"/><SpeedProfileEntry speed="0" time="3"/>'
    '</SpeedProfileAction></LongitudinalAction>',
    '<LateralAction><LateralDistanceAction entityRef="Ego" distance="3" freespace="false" '
    'continuous="true"><DynamicConstraints maxAcceleration="2" maxSpeed="1"/>'
    '</LateralDistanceAction></LateralAction>',
    '<SynchronizeAction masterEntityRef="Ego" targetToleranceMaster="1" targetTolerance="1">'
    '<TargetPositionMaster>' + BARE.format(100) + '</TargetPositionMaster>'
    '<TargetPosition>' + BARE.format(120) + '</TargetPosition>'
    '<FinalSpeed><RelativeSpeedToMaster value="2" speedTargetValueType="delta">'
    '<TargetDistanceSteadyState distance="5"/></RelativeSpeedToMaster></FinalSpeed>'
    '</SynchronizeAction>',
    '<ControllerAction><OverrideControllerValueAction>'
    '<Throttle active="true" value="0.3" maxRate="2"/>'
    '<Brake active="false"><BrakePercent value="0.5" maxRate="1"/></Brake>'
    '<Clutch active="false" value="0"/></OverrideControllerValueAction></ControllerAction>',
    '<RoutingAction><FollowTrajectoryAction><TrajectoryRef><Trajectory name="T" '
    'closed="false"><Shape>{shape}</Shape></Trajectory></TrajectoryRef>'
    '<TimeReference><None/></TimeReference><TrajectoryFollowingMode '
    'followingMode="position"/></FollowTrajectoryAction></RoutingAction>',
    '<RoutingAction><AssignRouteAction><Route name="R" closed="false"><Waypoint '
    'routeStrategy="shortest">' + POS.format(0) + '</Waypoint></Route></AssignRouteAction>'
    '</RoutingAction>',
    '<TrailerAction><ConnectTrailerAction trailerRef="Ego"/></TrailerAction>',
    '<VisibilityAction graphics="false" traffic="true" sensors="false"/>',
    '<AppearanceAction><LightStateAction transitionTime="0.5"><LightType><VehicleLight '
    'vehicleLightType="warningLights"/></LightType><LightState mode="flashing" '
    'luminousIntensity="100" flashingOnDuration="0.5" flashingOffDuration="0.5"><Color '
    'colorType="yellow"><ColorRgb red="1" green="0.8" blue="0"/></Color></LightState>'
    '</LightStateAction></AppearanceAction>',
]
SHAPES = [
    '<Polyline><Vertex time="0">' + POS.format(0) + '</Vertex><Vertex time="2">'
    + POS.format(20) + '</Vertex></Polyline>',
    '<Clothoid curvature="0.01" curvaturePrime="0.001" length="50" startTime="0" '
    'stopTime="5">' + POS.format(0) + '</Clothoid>',
    '<ClothoidSpline timeEnd="6"><ClothoidSplineSegment curvatureStart="0" '
    'curvatureEnd="0.02" length="30" timeStart="0"><PositionStart>' + BARE.format(0)
    + '</PositionStart></ClothoidSplineSegment><ClothoidSplineSegment curvatureStart="0.02" '
    'curvatureEnd="0" length="30"/></ClothoidSpline>',
    '<Nurbs order="3">' + "".join(
        f'<ControlPoint time="{i}" weight="1">{POS.format(10 * i)}</ControlPoint>'
        for i in range(4)) + "".join(f'<Knot value="{k}"/>' for k in (0, 0, 0, 1, 2, 2, 2))
    + '</Nurbs>',
]
GLOBALS = [
    '<EnvironmentAction><Environment name="E"><TimeOfDay animation="false" '
    'dateTime="2023-06-01T12:00:00"/><Weather fractionalCloudCover="twoOktas" '
    'temperature="290" atmosphericPressure="101325"><Sun azimuth="1" elevation="0.5" '
    'illuminance="10000"/><Fog visualRange="500"/><Precipitation precipitationType="rain" '
    'precipitationIntensity="2"/><Wind direction="1" speed="5"/></Weather><RoadCondition '
    'frictionScaleFactor="0.8" wetness="wetWithPuddles"/></Environment></EnvironmentAction>',
    '<VariableAction variableRef="v"><ModifyAction><Rule><AddValue value="2"/></Rule>'
    '</ModifyAction></VariableAction>',
    '<VariableAction variableRef="b"><SetAction value="true"/></VariableAction>',
    '<ParameterAction parameterRef="Speed"><ModifyAction><Rule><MultiplyByValue value="2"/>'
    '</Rule></ModifyAction></ParameterAction>',
    '<EntityAction entityRef="Ego"><AddEntityAction>' + POS.format(5)
    + '</AddEntityAction></EntityAction>',
    '<EntityAction entityRef="Ego"><DeleteEntityAction/></EntityAction>',
    '<InfrastructureAction><TrafficSignalAction><TrafficSignalStateAction name="1" '
    'state="red"/></TrafficSignalAction></InfrastructureAction>',
]
CONDITIONS = [
    '<ByValueCondition><VariableCondition variableRef="v" value="3" rule="greaterThan"/>'
    '</ByValueCondition>',
    '<ByValueCondition><TimeOfDayCondition dateTime="2023-06-01T12:00:05" '
    'rule="greaterThan"/></ByValueCondition>',
    '<ByValueCondition><TrafficSignalCondition name="1" state="green"/></ByValueCondition>',
    '<ByEntityCondition><TriggeringEntities triggeringEntitiesRule="any"><EntityRef '
    'entityRef="Ego"/></TriggeringEntities><EntityCondition><AccelerationCondition '
    'value="1" rule="greaterThan" direction="longitudinal"/></EntityCondition>'
    '</ByEntityCondition>',
]
HOSTILE = st.sampled_from(["1e999", "-1e999", "NaN", "INF", "-1", "0", "1e9", "-0.0",
                           "9" * 500, "", "x", "${1/0}", "$missing", "Ego", "v", "2.5"])


@st.composite
def _mutated(draw: st.DrawFn, text: str) -> str:
    """`text` (one element) unchanged or malformed once."""
    root = ET.fromstring(text)
    nodes = list(root.iter())
    node = nodes[draw(st.integers(0, len(nodes) - 1))]
    kind = draw(st.sampled_from(["none", "set", "drop_attr", "drop_child", "repeat_child",
                                 "foreign_child"]))
    if kind == "set" and node.attrib:
        node.attrib[draw(st.sampled_from(sorted(node.attrib)))] = draw(HOSTILE)
    elif kind == "drop_attr" and node.attrib:
        del node.attrib[draw(st.sampled_from(sorted(node.attrib)))]
    elif kind in ("drop_child", "repeat_child") and len(node):
        child = node[draw(st.integers(0, len(node) - 1))]
        if kind == "drop_child":
            node.remove(child)
        else:
            node.extend([child] * draw(st.integers(1, 50)))
    elif kind == "foreign_child":
        node.append(ET.Element(draw(st.sampled_from(["Foo", "UserDefinedAction", "Route",
                                                     "Trailer", "DomeImage"]))))
    return ET.tostring(root, encoding="unicode")


def _file(action: str | None = None, global_action: str | None = None,
          condition: str | None = None) -> str:
    text = MINIMAL.replace("<CatalogLocations>", VARIABLES + "<CatalogLocations>", 1)
    if action is not None:
        text = EVENT_ACTION.sub(lambda _: f"<PrivateAction>{action}</PrivateAction>", text,
                                count=1)
    if global_action is not None:
        text = EVENT_ACTION.sub(lambda _: f"<GlobalAction>{global_action}</GlobalAction>",
                                text, count=1)
    if condition is not None:
        text = EVENT_CONDITION.sub(lambda _: condition, text, count=1)
    return text


def _loads_or_one_line_error(tmp_path: Path, text: str) -> None:
    path = tmp_path / "fuzz.xosc"
    path.write_text(text, encoding="utf-8")
    try:
        load_openscenario(path)
    except ScenarioError as exc:
        assert "\n" not in str(exc)


@st.composite
def _private_action(draw: st.DrawFn) -> str:
    template = draw(st.sampled_from(ACTIONS))
    if "{shape}" in template:
        template = template.replace("{shape}", draw(st.sampled_from(SHAPES)))
    return draw(_mutated(template))


@FUZZ
@given(_private_action())
def test_a_new_private_action_loads_or_is_one_line(tmp_path_factory: pytest.TempPathFactory,
                                                   action: str) -> None:
    _loads_or_one_line_error(tmp_path_factory.mktemp("a"), _file(action=action))


@FUZZ
@given(st.sampled_from(GLOBALS).flatmap(_mutated))
def test_a_global_action_loads_or_is_one_line(tmp_path_factory: pytest.TempPathFactory,
                                              action: str) -> None:
    _loads_or_one_line_error(tmp_path_factory.mktemp("g"), _file(global_action=action))


@FUZZ
@given(st.sampled_from(CONDITIONS).flatmap(_mutated))
def test_a_new_condition_loads_or_is_one_line(tmp_path_factory: pytest.TempPathFactory,
                                              condition: str) -> None:
    _loads_or_one_line_error(tmp_path_factory.mktemp("c"), _file(condition=condition))


DISTRIBUTIONS = [
    '<Deterministic><DeterministicSingleParameterDistribution parameterName="Speed">'
    '<DistributionRange stepWidth="0.5"><Range lowerLimit="1" upperLimit="5"/>'
    '</DistributionRange></DeterministicSingleParameterDistribution>'
    '<DeterministicSingleParameterDistribution parameterName="Speed">'
    '<DistributionSet><Element value="1"/><Element value="2"/></DistributionSet>'
    '</DeterministicSingleParameterDistribution>'
    '<DeterministicMultiParameterDistribution><ValueSetDistribution><ParameterValueSet>'
    '<ParameterAssignment parameterRef="Speed" value="3"/></ParameterValueSet>'
    '</ValueSetDistribution></DeterministicMultiParameterDistribution></Deterministic>',
    '<Stochastic numberOfTestRuns="20" randomSeed="7"><StochasticDistribution '
    'parameterName="Speed"><NormalDistribution expectedValue="10" variance="4"><Range '
    'lowerLimit="5" upperLimit="15"/></NormalDistribution></StochasticDistribution>'
    '<StochasticDistribution parameterName="Speed"><ProbabilityDistributionSet><Element '
    'value="1" weight="1"/><Element value="2" weight="3"/></ProbabilityDistributionSet>'
    '</StochasticDistribution><StochasticDistribution parameterName="Speed">'
    '<Histogram><Bin weight="1"><Range lowerLimit="0" upperLimit="1"/></Bin></Histogram>'
    '</StochasticDistribution><StochasticDistribution parameterName="Speed">'
    '<UniformDistribution><Range lowerLimit="0" upperLimit="1"/></UniformDistribution>'
    '</StochasticDistribution><StochasticDistribution parameterName="Speed">'
    '<PoissonDistribution expectedValue="3"><Range lowerLimit="0" upperLimit="9"/>'
    '</PoissonDistribution></StochasticDistribution><StochasticDistribution '
    'parameterName="Speed"><LogNormalDistribution expectedValue="1" variance="0.5"/>'
    '</StochasticDistribution></Stochastic>',
]


@FUZZ
@given(st.sampled_from(DISTRIBUTIONS).flatmap(_mutated), st.sampled_from(["0", "2", "3"]))
def test_a_distribution_file_expands_within_its_bound_or_is_one_line(
        tmp_path_factory: pytest.TempPathFactory, body: str, minor: str) -> None:
    folder = tmp_path_factory.mktemp("d")
    (folder / "base.xosc").write_text(MINIMAL, encoding="utf-8")
    path = folder / "dist.xosc"
    path.write_text('<?xml version="1.0"?><OpenSCENARIO><FileHeader revMajor="1" '
                    f'revMinor="{minor}"/><ParameterValueDistribution><ScenarioFile '
                    f'filepath="base.xosc"/>{body}</ParameterValueDistribution>'
                    '</OpenSCENARIO>', encoding="utf-8")
    try:
        distribution = load_distribution(path)
    except ScenarioError as exc:
        assert "\n" not in str(exc)
        return
    assert 1 <= len(distribution.runs) <= MAX_RUNS


@pytest.mark.parametrize("kind", ["NormalDistribution", "LogNormalDistribution"])
def test_a_variance_of_minus_zero_draws_the_expected_value(tmp_path: Path, kind: str) -> None:
    """-0.0 is >= 0: no spread (numpy's sigma must not be -0.0)."""
    (tmp_path / "base.xosc").write_text(MINIMAL, encoding="utf-8")
    path = tmp_path / "dist.xosc"
    path.write_text('<?xml version="1.0"?><OpenSCENARIO><FileHeader revMajor="1" '
                    'revMinor="2"/><ParameterValueDistribution><ScenarioFile '
                    'filepath="base.xosc"/><Stochastic numberOfTestRuns="3" randomSeed="1">'
                    f'<StochasticDistribution parameterName="Speed"><{kind} '
                    f'expectedValue="2" variance="-0.0"/></StochasticDistribution>'
                    '</Stochastic></ParameterValueDistribution></OpenSCENARIO>',
                    encoding="utf-8")
    runs = load_distribution(path).runs
    assert [float(run.parameters[0][1]) for run in runs] == pytest.approx([2.0] * 3)


def test_a_uniform_range_up_to_minus_zero_draws_zero(tmp_path: Path) -> None:
    """[0, -0.0] is not reversed: every draw is 0 (numpy's uniform refused high - low < 0)."""
    (tmp_path / "base.xosc").write_text(MINIMAL, encoding="utf-8")
    path = tmp_path / "dist.xosc"
    path.write_text('<?xml version="1.0"?><OpenSCENARIO><FileHeader revMajor="1" '
                    'revMinor="2"/><ParameterValueDistribution><ScenarioFile '
                    'filepath="base.xosc"/><Stochastic numberOfTestRuns="2" randomSeed="1">'
                    '<StochasticDistribution parameterName="Speed"><UniformDistribution>'
                    '<Range lowerLimit="0" upperLimit="-0.0"/></UniformDistribution>'
                    '</StochasticDistribution></Stochastic></ParameterValueDistribution>'
                    '</OpenSCENARIO>', encoding="utf-8")
    assert [float(run.parameters[0][1]) for run in load_distribution(path).runs] == [0.0, 0.0]
