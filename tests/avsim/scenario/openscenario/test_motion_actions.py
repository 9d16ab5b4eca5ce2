"""Parse tables of the motion actions: SynchronizeAction, LateralDistanceAction,
SpeedProfileAction, TeleportAction in a story, and the trajectory shapes (Clothoid,
ClothoidSpline, Nurbs) and TrajectoryPosition; their bounds are one-line refusals."""

from __future__ import annotations

from pathlib import Path

import pytest

from avsim.scenario.errors import ScenarioError
from avsim.scenario.openscenario import load_openscenario
from avsim.scenario.openscenario.limits import MAX_TRAJECTORY_POINTS
from avsim.scenario.openscenario.model import (
    Clothoid,
    ClothoidSpline,
    ClothoidSplineSegment,
    ControlPoint,
    DynamicConstraints,
    FinalSpeed,
    FollowTrajectoryAction,
    LateralDistanceAction,
    Nurbs,
    PrivateAction,
    SpeedProfileAction,
    SpeedProfileEntry,
    SteadyState,
    SynchronizeAction,
    TeleportAction,
    TrajectoryPosition,
    WorldPosition,
)

DATA = Path(__file__).parent / "data"
_MINIMAL = (DATA / "minimal.xosc").read_text()
SPEED_ACTION = _MINIMAL[
    _MINIMAL.index("<LongitudinalAction>") : _MINIMAL.index("</LongitudinalAction>") + 21
]
W0 = '<Position><WorldPosition x="0" y="0" h="0"/></Position>'
W1 = '<Position><WorldPosition x="10" y="0"/></Position>'


def story_action(tmp_path: Path, xml: str) -> PrivateAction:
    path = tmp_path / "variant.xosc"
    path.write_text(_MINIMAL.replace(SPEED_ACTION, xml, 1))
    scenario = load_openscenario(path)
    [(_, action)] = list(scenario.storyboard.story_actions())
    assert action.private_action is not None
    return action.private_action


def refusal(tmp_path: Path, xml: str) -> str:
    path = tmp_path / "variant.xosc"
    path.write_text(_MINIMAL.replace(SPEED_ACTION, xml, 1))
    with pytest.raises(ScenarioError) as info:
        load_openscenario(path)
    text = str(info.value)
    assert "\n" not in text
    return text


def world(x: float, y: float, h: float | None = None) -> WorldPosition:
    return WorldPosition(x, y, None, h, None, None)


def test_synchronize_with_a_final_speed_and_a_steady_state(tmp_path: Path) -> None:
    action = story_action(tmp_path, """
      <SynchronizeAction masterEntityRef="Ego" targetToleranceMaster="0.5" targetTolerance="1">
        <TargetPositionMaster><WorldPosition x="50" y="0"/></TargetPositionMaster>
        <TargetPosition><WorldPosition x="60" y="3"/></TargetPosition>
        <FinalSpeed><AbsoluteSpeed value="5"><TargetDistanceSteadyState distance="4"/>
        </AbsoluteSpeed></FinalSpeed>
      </SynchronizeAction>""")
    assert action == SynchronizeAction(
        "Ego", world(50.0, 0.0), world(60.0, 3.0),
        FinalSpeed(5.0, "absolute", SteadyState(4.0, None)), 0.5, 1.0)


def test_synchronize_relative_to_the_master_and_without_a_final_speed(tmp_path: Path) -> None:
    action = story_action(tmp_path, """
      <SynchronizeAction masterEntityRef="Ego">
        <TargetPositionMaster><WorldPosition x="50" y="0"/></TargetPositionMaster>
        <TargetPosition><WorldPosition x="60" y="3"/></TargetPosition>
        <FinalSpeed><RelativeSpeedToMaster speedTargetValueType="factor" value="0.5">
          <TargetTimeSteadyState time="2"/></RelativeSpeedToMaster></FinalSpeed>
      </SynchronizeAction>""")
    assert isinstance(action, SynchronizeAction)
    assert action.final_speed == FinalSpeed(0.5, "factor", SteadyState(None, 2.0))
    assert (action.tolerance_master, action.tolerance) == (0.0, 0.0)
    bare = story_action(tmp_path, """
      <SynchronizeAction masterEntityRef="Ego">
        <TargetPositionMaster><WorldPosition x="50" y="0"/></TargetPositionMaster>
        <TargetPosition><WorldPosition x="60" y="3"/></TargetPosition>
      </SynchronizeAction>""")
    assert isinstance(bare, SynchronizeAction) and bare.final_speed is None


def test_lateral_distance(tmp_path: Path) -> None:
    action = story_action(tmp_path, """<LateralAction>
      <LateralDistanceAction entityRef="Ego" distance="3.5" freespace="false" continuous="true"
          coordinateSystem="lane" displacement="leftToReferencedEntity">
        <DynamicConstraints maxLateralAcc="1" maxAcceleration="1.5" maxSpeed="2"/>
      </LateralDistanceAction></LateralAction>""")
    assert action == LateralDistanceAction(
        "Ego", 3.5, False, True, "lane", "leftToReferencedEntity",
        DynamicConstraints(1.5, None, 2.0, None, None))


def test_speed_profile(tmp_path: Path) -> None:
    action = story_action(tmp_path, """<LongitudinalAction>
      <SpeedProfileAction followingMode="position">
        <SpeedProfileEntry speed="10" time="2"/>
        <SpeedProfileEntry speed="4"/>
      </SpeedProfileAction></LongitudinalAction>""")
    assert action == SpeedProfileAction(
        None, "position", (SpeedProfileEntry(10.0, 2.0), SpeedProfileEntry(4.0, None)), None)


def test_teleport_in_a_story(tmp_path: Path) -> None:
    action = story_action(tmp_path, f"<TeleportAction>{W1}</TeleportAction>")
    assert action == TeleportAction(world(10.0, 0.0))


def trajectory_action(shape: str) -> str:
    return ("<RoutingAction><FollowTrajectoryAction><TrajectoryRef>"
            f"<Trajectory name='t' closed='false'><Shape>{shape}</Shape></Trajectory>"
            "</TrajectoryRef><TimeReference><None/></TimeReference>"
            "<TrajectoryFollowingMode followingMode='follow'/>"
            "</FollowTrajectoryAction></RoutingAction>")


def shape_of(tmp_path: Path, shape: str) -> object:
    action = story_action(tmp_path, trajectory_action(shape))
    assert isinstance(action, FollowTrajectoryAction)
    return action.trajectory.shape


def test_clothoid_with_curvature_dot_or_prime(tmp_path: Path) -> None:
    old = shape_of(tmp_path, f'<Clothoid curvature="0.01" curvatureDot="0.001" length="20" '
                             f'startTime="1" stopTime="3">{W0}</Clothoid>')
    assert old == Clothoid(0.01, 0.001, 20.0, 1.0, 3.0, world(0.0, 0.0, 0.0))
    new = shape_of(tmp_path, '<Clothoid curvature="0" curvaturePrime="0.002" length="5"/>')
    assert new == Clothoid(0.0, 0.002, 5.0, None, None, None)


def test_clothoid_spline(tmp_path: Path) -> None:
    shape = shape_of(tmp_path, f"""<ClothoidSpline timeEnd="4">
        <ClothoidSplineSegment curvatureStart="0" curvatureEnd="0.1" length="10" timeStart="0">
          <PositionStart>{W0[10:-11]}</PositionStart></ClothoidSplineSegment>
        <ClothoidSplineSegment curvatureStart="0.1" curvatureEnd="0" length="10"
                               hOffset="0.1" timeStart="2"/>
      </ClothoidSpline>""")
    assert shape == ClothoidSpline((
        ClothoidSplineSegment(0.0, 0.1, 10.0, 0.0, 0.0, world(0.0, 0.0, 0.0)),
        ClothoidSplineSegment(0.1, 0.0, 10.0, 0.1, 2.0, None)), 4.0)


def test_nurbs(tmp_path: Path) -> None:
    shape = shape_of(tmp_path, f"""<Nurbs order="2">
        <ControlPoint time="0">{W0}</ControlPoint>
        <ControlPoint weight="2" time="1">{W1}</ControlPoint>
        <Knot value="0"/><Knot value="0"/><Knot value="1"/><Knot value="1"/></Nurbs>""")
    assert shape == Nurbs(2, (ControlPoint(0.0, 1.0, world(0.0, 0.0, 0.0)),
                              ControlPoint(1.0, 2.0, world(10.0, 0.0))), (0.0, 0.0, 1.0, 1.0))


def test_trajectory_position(tmp_path: Path) -> None:
    line = (f"<Polyline><Vertex>{W0}</Vertex><Vertex>{W1}</Vertex></Polyline>")
    action = story_action(tmp_path, f"""<TeleportAction><Position>
        <TrajectoryPosition s="4" t="1"><TrajectoryRef><Trajectory name="t" closed="false">
        <Shape>{line}</Shape></Trajectory></TrajectoryRef></TrajectoryPosition>
        </Position></TeleportAction>""")
    assert isinstance(action, TeleportAction)
    position = action.position
    assert isinstance(position, TrajectoryPosition)
    assert (position.s, position.t, position.orientation) == (4.0, 1.0, None)


@pytest.mark.parametrize(("shape", "problem"), [
    (f'<Nurbs order="2"><ControlPoint>{W0}</ControlPoint><ControlPoint>{W1}</ControlPoint>'
     '<Knot value="0"/><Knot value="1"/></Nurbs>', "needs 4 Knot elements"),
    (f'<Nurbs order="3"><ControlPoint>{W0}</ControlPoint><ControlPoint>{W1}</ControlPoint>'
     '<Knot value="0"/></Nurbs>', "needs at least 3 ControlPoint"),
    (f'<Nurbs order="2"><ControlPoint weight="0">{W0}</ControlPoint><ControlPoint>{W1}'
     '</ControlPoint><Knot value="0"/><Knot value="0"/><Knot value="1"/><Knot value="1"/>'
     '</Nurbs>', "weight: must be > 0"),
    (f'<Nurbs order="2"><ControlPoint>{W0}</ControlPoint><ControlPoint>{W1}</ControlPoint>'
     '<Knot value="0"/><Knot value="1"/><Knot value="0"/><Knot value="1"/></Nurbs>',
     "must not decrease"),
    ('<Clothoid curvature="0" length="30000"/>', "length: must be in [0, 20000] m"),
    ('<Clothoid curvature="0" length="0"/>', "must be > 0"),
    ('<Clothoid curvature="50" length="1"/>', "curvature: must be in [-10, 10] 1/m"),
    (f"<Polyline><Vertex>{W0}</Vertex></Polyline>", "needs at least 2 Vertex"),
])
def test_shapes_out_of_bounds_are_refused(tmp_path: Path, shape: str, problem: str) -> None:
    assert problem in refusal(tmp_path, trajectory_action(shape))


def test_a_polyline_over_the_point_bound_is_refused_before_reading_its_vertices(
        tmp_path: Path) -> None:
    vertices = f"<Vertex>{W0}</Vertex>" * (MAX_TRAJECTORY_POINTS + 1)
    text = refusal(tmp_path, trajectory_action(f"<Polyline>{vertices}</Polyline>"))
    assert f"must have <= {MAX_TRAJECTORY_POINTS} Vertex elements" in text


def test_a_speed_profile_needs_an_entry(tmp_path: Path) -> None:
    text = refusal(tmp_path, "<LongitudinalAction><SpeedProfileAction followingMode='follow'/>"
                             "</LongitudinalAction>")
    assert text.endswith("SpeedProfileAction: needs at least one SpeedProfileEntry")

