"""The motion actions played on a real world (`--profile none`), one actor each, in one
run of `data/motion_actions.xosc` (filled in here; the ego drives by in lane -1): a
SynchronizeAction brings its actor to its target when the master reaches its own and
leaves it at the final speed; a SpeedProfileAction hits its speeds at their times; a
LateralDistanceAction keeps its distance to the ego; a TeleportAction in a story moves a
standing actor at once; a Clothoid trajectory ends where its closed form says."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy.special import fresnel

from avsim.run.runner import Runner, RunResult
from avsim.scenario.load import load_scenario

pytestmark = pytest.mark.slow
DATA = Path(__file__).parent / "data"
RECORD_DT = 0.05  # [s] the log's step (recording at 20 Hz)
LANE1, LANE2 = 3.5, 0.0  # [m] lanes -1 and -2: centres from the route's reference line
#   (the rightmost lane's centre)
ROUTE_Y = -5.25  # [m] the route's reference line in the map (straight.xodr: along +x)
ACTORS = ("Master", "Sync", "Profile", "Lateral", "Jumper", "Curve")
START = {"Ego": ("-1", 20.0, 10.0), "Master": ("-2", 300.0, 15.0), "Sync": ("-2", 100.0, 5.0),
         "Profile": ("-1", 400.0, 10.0), "Lateral": ("-2", 500.0, 10.0),
         "Jumper": ("-2", 600.0, 0.0), "Curve": ("-2", 800.0, 10.0)}
CURVE_RATE, CURVE_LENGTH = 1e-4, 40.0  # [1/m^2], [m]


def vehicle(name: str) -> str:
    return f"""<ScenarioObject name="{name}"><Vehicle name="{name}_car" vehicleCategory="car">
      <BoundingBox><Center x="0" y="0" z="0.75"/><Dimensions width="1.8" length="4.5"
        height="1.5"/></BoundingBox>
      <Performance maxSpeed="70" maxAcceleration="5" maxDeceleration="10"/>
      <Axles><FrontAxle maxSteering="0.5" wheelDiameter="0.6" trackWidth="1.6" positionX="2.8"
        positionZ="0.3"/><RearAxle maxSteering="0" wheelDiameter="0.6" trackWidth="1.6"
        positionX="0" positionZ="0.3"/></Axles><Properties/></Vehicle></ScenarioObject>"""


def lane(lane_id: str, s: float) -> str:
    return f'<LanePosition roadId="0" laneId="{lane_id}" s="{s}" offset="0"/>'


def init(name: str) -> str:
    return init_at(name, *START[name])


def init_at(name: str, lane_id: str, s: float, v: float) -> str:
    return f"""<Private entityRef="{name}">
      <PrivateAction><TeleportAction><Position>{lane(lane_id, s)}</Position></TeleportAction>
      </PrivateAction>
      <PrivateAction><LongitudinalAction><SpeedAction>
        <SpeedActionDynamics dynamicsShape="step" dynamicsDimension="time" value="0"/>
        <SpeedActionTarget><AbsoluteTargetSpeed value="{v}"/></SpeedActionTarget>
      </SpeedAction></LongitudinalAction></PrivateAction></Private>"""


def group(actor: str, action: str, at: float) -> str:
    return f"""<ManeuverGroup maximumExecutionCount="1" name="{actor}Group">
      <Actors selectTriggeringEntities="false"><EntityRef entityRef="{actor}"/></Actors>
      <Maneuver name="{actor}Maneuver"><Event name="{actor}Event" priority="override">
        <Action name="{actor}Action"><PrivateAction>{action}</PrivateAction></Action>
        <StartTrigger><ConditionGroup><Condition name="{actor}At" delay="0"
          conditionEdge="none"><ByValueCondition><SimulationTimeCondition value="{at}"
          rule="greaterOrEqual"/></ByValueCondition></Condition></ConditionGroup>
        </StartTrigger></Event></Maneuver></ManeuverGroup>"""


ACTIONS = {
    "Sync": (f"""<SynchronizeAction masterEntityRef="Master">
        <TargetPositionMaster>{lane("-2", 450.0)}</TargetPositionMaster>
        <TargetPosition>{lane("-2", 190.0)}</TargetPosition>
        <FinalSpeed><AbsoluteSpeed value="8"/></FinalSpeed></SynchronizeAction>""", 0.0),
    "Profile": ("""<LongitudinalAction><SpeedProfileAction followingMode="position">
        <SpeedProfileEntry speed="15" time="2"/><SpeedProfileEntry speed="5" time="4"/>
        </SpeedProfileAction></LongitudinalAction>""", 1.0),
    "Lateral": ("""<LateralAction><LateralDistanceAction entityRef="Ego" distance="4"
        freespace="false" continuous="true"><DynamicConstraints maxSpeed="1"/>
        </LateralDistanceAction></LateralAction>""", 0.0),
    "Jumper": (f"<TeleportAction><Position>{lane('-2', 700.0)}</Position></TeleportAction>",
               2.0),
    "Curve": (f"""<RoutingAction><FollowTrajectoryAction><TrajectoryRef>
        <Trajectory name="bend" closed="false"><Shape><Clothoid curvature="0"
          curvaturePrime="{CURVE_RATE}" length="{CURVE_LENGTH}"/></Shape></Trajectory>
        </TrajectoryRef><TimeReference><None/></TimeReference>
        <TrajectoryFollowingMode followingMode="position"/></FollowTrajectoryAction>
        </RoutingAction>""", 1.0),
}


def scenario_file(folder: Path) -> Path:
    text = (DATA / "motion_actions.xosc").read_text()
    text = text.replace("ENTITIES", "".join(vehicle(n) for n in ("Ego", *ACTORS)))
    text = text.replace("INIT", "".join(init(n) for n in ("Ego", *ACTORS)))
    text = text.replace("GROUPS", "".join(group(a, x, t) for a, (x, t) in ACTIONS.items()))
    shutil.copy(DATA / "straight.xodr", folder / "straight.xodr")
    path = folder / "motion.xosc"
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> RunResult:
    path = scenario_file(tmp_path_factory.mktemp("motion"))
    return Runner(load_scenario(path, {"duration": 12.0}), None, profile=None).run()


def track(result: RunResult, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t, station, offset) of an actor's centre (= its reference point here)."""
    k = ACTORS.index(name)
    return (result.log.array("t"), np.array(result.log.actor_station)[:, k],
            np.array(result.log.actor_offset)[:, k])


def crossing(t: np.ndarray, s: np.ndarray, at: float) -> float:
    """[s] when s first reaches `at` (linear between log rows)."""
    i = int(np.flatnonzero(s >= at)[0])
    return float(t[i - 1] + (at - s[i - 1]) / (s[i] - s[i - 1]) * (t[i] - t[i - 1]))


def test_synchronize_arrives_with_the_master_at_the_final_speed(run: RunResult) -> None:
    t, master, _ = track(run, "Master")
    _, sync, offset = track(run, "Sync")
    assert crossing(t, sync, 190.0) == pytest.approx(crossing(t, master, 450.0), abs=RECORD_DT)
    after = t > crossing(t, sync, 190.0) + 0.2
    v = np.diff(sync) / np.diff(t)
    assert v[after[1:]] == pytest.approx(8.0, abs=1e-6)
    assert np.all(v > 0.0)  # a convex profile: never backwards
    assert np.max(v) > 9.0  # it had to rush: 90 m in 10 s from 5 m/s
    assert offset == pytest.approx(LANE2, abs=1e-9)


def test_speed_profile_hits_its_speeds_at_their_times(run: RunResult) -> None:
    t, s, _ = track(run, "Profile")
    v = np.diff(s) / np.diff(t)
    mid = 0.5 * (t[1:] + t[:-1])
    for when, speed in ((0.5, 10.0), (2.0, 12.5), (3.0, 15.0), (5.0, 10.0), (7.0, 5.0),
                        (10.0, 5.0)):
        assert np.interp(when, mid, v) == pytest.approx(speed, abs=0.1), when


def test_lateral_distance_is_kept_right_of_the_ego(run: RunResult) -> None:
    t, _, offset = track(run, "Lateral")
    ego = run.log.array("y") - ROUTE_Y  # the ego's centre from the route's reference line
    late = t > 2.5  # caught up from lane -2 at 1 m/s
    assert offset[late] == pytest.approx(ego[late] - 4.0, abs=0.15)
    lateral_speed = np.abs(np.diff(offset)) / np.diff(t)
    assert np.max(lateral_speed) <= 1.0 + 1e-6  # its maxSpeed


def test_teleport_in_a_story_moves_a_standing_actor_at_once(run: RunResult) -> None:
    t, s, offset = track(run, "Jumper")
    assert np.all(s[t < 1.95] == pytest.approx(600.0))
    assert np.all(s[t > 2.05] == pytest.approx(700.0))
    assert offset == pytest.approx(LANE2, abs=1e-9)


def test_a_clothoid_from_the_actors_pose_ends_at_its_closed_form(run: RunResult) -> None:
    _t, s, offset = track(run, "Curve")
    a = math.sqrt(math.pi / CURVE_RATE)
    dy, dx = (a * v for v in fresnel(CURVE_LENGTH / a))
    end = 800.0 + 10.0 * 1.0 + dx  # it drove 1 s before the clothoid started
    i = int(np.argmin(np.abs(s - end)))
    assert offset[i] == pytest.approx(LANE2 + dy, abs=0.05)
    assert offset[-1] == pytest.approx(LANE2 + dy, abs=0.05)  # then straight on
