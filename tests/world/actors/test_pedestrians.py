"""Pedestrians: the `walk` action (`world.actors.behaviour`), their bodies and ground truth in
the world (`world.actors.actor_set`), and scenario files with pedestrians and walks
(`avsim.scenario.load`).

The pure kinematics follow `tests/world/actors/test_behaviour.py`'s convention: at step k the clock
reads t = k / RATE; triggers are checked at t, then the motion is stepped with (t, dt). The
world tests run the real `World` (no sensors) at its own rates.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from avsim.scenario import load as scenario_module
from avsim.scenario.load import ScenarioError, load_scenario
from world.actors.actor_set import ActorPoses
from world.actors.behaviour import (
    LATERAL_ACCEL,
    PEDESTRIAN_TURN_RATE,
    NpcMotion,
    TriggerContext,
)
from world.actors.shapes.walker import walker_pose
from world.core.rates import TRIGGER_RATE
from world.spec import (
    Action,
    ActionSpec,
    ActorType,
    AfterTrigger,
    EgoStationTrigger,
    GapTrigger,
    LaneChangeAction,
    TimeTrigger,
    Trigger,
    WalkAction,
)
from world.world import World

RATE = 120  # [Hz] the world's NPC motion rate
DT = 1.0 / RATE  # [s]
LANE_WIDTH = 3.5  # [m]
KPH = 1000.0 / 3600.0  # [m/s] per km/h
WALK = 5.0 * KPH  # [m/s] the format's default walking speed
EPS = 1e-9
ACCEL_TOL = 1e-3  # [m/s^2]
FAR = 1e6  # [m] a gap / station that never triggers anything
HALF_PI = 0.5 * math.pi


def lane_offset(lane: int, s: float) -> float:
    """[m] lane centres of a straight road: lane i at 3.5 i left of the reference line."""
    return LANE_WIDTH * lane


def ctx(t: float, ego_s: float = -FAR, gap: float = FAR) -> TriggerContext:
    return TriggerContext(t=t, ego_s=ego_s, gap=gap)


def walker(*actions: tuple[Trigger, Action], lane: int = 0, offset: float = -6.0,
           speed: float = 0.0, direction: int = 1) -> NpcMotion:
    """A pedestrian `offset` [m] from lane `lane`'s centre at s = 100 m."""
    specs = tuple(ActionSpec(trigger=trigger, action=action) for trigger, action in actions)
    return NpcMotion(s=100.0, offset=lane_offset(lane, 100.0) + offset, speed=speed,
                     direction=direction, actions=specs, lane=lane, pedestrian=True)


@dataclass
class Trace:
    t: list[float] = field(default_factory=list)  # [s]
    s: list[float] = field(default_factory=list)  # [m]
    offset: list[float] = field(default_factory=list)  # [m]
    lateral_speed: list[float] = field(default_factory=list)  # [m/s]
    heading: list[float] = field(default_factory=list)  # [rad] relative to the lane direction
    started: list[tuple[float, int]] = field(default_factory=list)


def simulate(m: NpcMotion, duration: float,
             context: Callable[[float], TriggerContext] = ctx) -> Trace:
    """Check triggers and step `m` for `duration` [s]; `context(t)` gives the trigger
    context (default: only time triggers can hold)."""
    make = context
    trace = Trace()
    for k in range(1, round(duration * RATE) + 1):
        t = k / RATE
        trace.started += [(t, i) for i in m.fire_due(make(t), lane_offset)]
        m.step(t, DT, 0.0)
        trace.t.append(t)
        trace.s.append(m.s)
        trace.offset.append(m.offset)
        trace.lateral_speed.append(m.lateral_speed)
        trace.heading.append(m.heading_offset)
    return trace


def walk_time(distance: float, speed: float) -> float:
    """[s] a trapezoidal walk: ramps of speed / a at both ends, the rest at speed."""
    return distance / speed + speed / LATERAL_ACCEL


def diffs(values: list[float]) -> list[float]:
    return [b - a for a, b in itertools.pairwise(values)]


# ---------------------------------------------------------------------------------------
# The walk action, kinematics
# ---------------------------------------------------------------------------------------

START = 1.0  # [s] trigger time
FROM, TO = -6.0, 9.0  # [m] from lane 0's centre: the pavement, across two lanes and beyond


@pytest.fixture(scope="module")
def crossing() -> tuple[NpcMotion, Trace]:
    m = walker((TimeTrigger(START), WalkAction(to_offset=TO, speed=WALK)))
    return m, simulate(m, START + walk_time(TO - FROM, WALK) + 3.0)


def test_walk_starts_at_its_trigger(crossing: tuple[NpcMotion, Trace]) -> None:
    m, trace = crossing
    assert trace.started == [(START, 0)] and m.fired_at == [START]
    i = trace.t.index(START)
    assert trace.offset[:i] == [FROM] * i  # stood still before
    assert trace.heading[:i] == [0.0] * i  # facing along its lane
    assert trace.offset[i] > FROM  # moves from the trigger's step on


def test_walk_moves_at_the_walking_speed(crossing: tuple[NpcMotion, Trace]) -> None:
    _, trace = crossing
    lateral = trace.lateral_speed
    assert max(lateral) == pytest.approx(WALK)  # reaches it
    assert max(lateral) <= WALK + EPS and min(lateral) >= 0.0  # never faster, never back
    cruising = [v for t, v in zip(trace.t, lateral, strict=True)
                if START + WALK / LATERAL_ACCEL + DT < t < START + (TO - FROM) / WALK - 0.05]
    assert len(cruising) > 8 * RATE  # ~9.9 of the ~11.7 s crossing at the walking speed
    assert all(v == pytest.approx(WALK, abs=EPS) for v in cruising)
    assert all(abs(a) / DT <= LATERAL_ACCEL + ACCEL_TOL for a in diffs([0.0, *lateral]))
    assert all(s == 100.0 for s in trace.s)  # straight across: the station does not change


def test_walk_stops_at_to_offset_and_stands(crossing: tuple[NpcMotion, Trace]) -> None:
    m, trace = crossing
    ended = m.ended_at[0]
    assert ended is not None
    assert ended == pytest.approx(START + walk_time(TO - FROM, WALK), abs=0.05)
    i = trace.t.index(ended)
    assert trace.offset[i] == pytest.approx(TO, abs=EPS)
    assert trace.offset[i:] == [trace.offset[i]] * (len(trace.t) - i)  # stands there
    assert trace.lateral_speed[-1] == 0.0 and m.speed == 0.0
    assert max(trace.offset) <= TO + EPS  # no overshoot


def test_walker_faces_the_walking_direction(crossing: tuple[NpcMotion, Trace]) -> None:
    m, trace = crossing
    turned = START + HALF_PI / PEDESTRIAN_TURN_RATE + 0.1  # [s] the turn takes 0.5 s
    walking = [h for t, h in zip(trace.t, trace.heading, strict=True)
               if turned <= t]
    assert all(h == pytest.approx(HALF_PI, abs=EPS) for h in walking)  # left, and stays
    assert m.heading_offset == pytest.approx(HALF_PI)  # still facing that way, standing
    rates = [abs(math.remainder(d, 2 * math.pi)) / DT for d in diffs([0.0, *trace.heading])]
    assert max(rates) <= PEDESTRIAN_TURN_RATE + 1e-6  # turns smoothly, never jumps


def test_walk_back_after_a_delay_turns_round() -> None:
    m = walker(
        (TimeTrigger(0.0), WalkAction(to_offset=-2.0, speed=WALK)),  # to the kerb...
        (AfterTrigger(index=0, delay=2.0), WalkAction(to_offset=-9.0, speed=2 * WALK)),  # back
    )
    trace = simulate(m, 12.0)
    first, second = m.ended_at
    assert first is not None and second is not None
    assert m.fired_at[1] == pytest.approx(first + 2.0, abs=DT + EPS)
    assert m.offset == pytest.approx(-9.0, abs=EPS)
    assert max(trace.lateral_speed) == pytest.approx(WALK)
    assert min(trace.lateral_speed) == pytest.approx(-2 * WALK)  # running back
    i = trace.t.index(first)
    assert trace.heading[i] == pytest.approx(HALF_PI)
    assert trace.heading[-1] == pytest.approx(-HALF_PI)  # facing the pavement it went back to


@pytest.mark.parametrize("lane", [0, 1])
def test_to_offset_is_from_the_actors_lane_centre(lane: int) -> None:
    m = walker((TimeTrigger(0.0), WalkAction(to_offset=1.0, speed=WALK)), lane=lane,
               offset=-1.0)
    simulate(m, 5.0)
    assert m.offset == pytest.approx(lane_offset(lane, 100.0) + 1.0, abs=EPS)
    assert m.heading_offset == pytest.approx(HALF_PI)


def test_to_offset_follows_a_lane_change() -> None:
    """An actor that changed lane walks to offsets from its new lane's centre."""
    m = walker((TimeTrigger(0.0), LaneChangeAction(to_lane=1, lateral_speed=2.0)),
               (AfterTrigger(index=0, delay=0.0), WalkAction(to_offset=-0.5, speed=WALK)),
               offset=0.0)
    simulate(m, 8.0)
    assert m.ended_at[1] is not None
    assert m.offset == pytest.approx(LANE_WIDTH - 0.5, abs=EPS)


def test_walking_right_faces_right() -> None:
    m = walker((TimeTrigger(0.0), WalkAction(to_offset=-5.0, speed=WALK)), offset=4.0)
    simulate(m, 10.0)
    assert m.offset == pytest.approx(-5.0, abs=EPS)
    assert m.heading_offset == pytest.approx(-HALF_PI)


def test_walking_along_and_across_faces_the_diagonal() -> None:
    m = walker((TimeTrigger(0.0), WalkAction(to_offset=6.0, speed=1.0)), offset=-6.0,
               speed=1.0)
    trace = simulate(m, 5.0)
    assert trace.lateral_speed[-1] == pytest.approx(1.0)
    assert trace.heading[-1] == pytest.approx(math.pi / 4)  # 1 m/s along, 1 m/s across
    assert trace.s[-1] == pytest.approx(105.0)


def test_pedestrian_on_an_oncoming_lane_faces_where_it_walks() -> None:
    """Against the route (direction -1) the body's yaw is the route heading + pi + the
    heading offset: walking to the route's left is facing the route's left."""
    m = walker((TimeTrigger(0.0), WalkAction(to_offset=3.0, speed=WALK)), offset=0.0,
               direction=-1)
    simulate(m, 6.0)
    assert m.offset == pytest.approx(3.0, abs=EPS)
    assert math.remainder(math.pi + m.heading_offset - HALF_PI, 2 * math.pi) == \
        pytest.approx(0.0, abs=1e-9)


def test_a_vehicle_keeps_its_heading_rule() -> None:
    """Not a pedestrian: at rest a vehicle points along its lane whatever it does."""
    m = NpcMotion(s=0.0, offset=0.0, speed=0.0, direction=1, lane=0,
                  actions=(ActionSpec(TimeTrigger(0.0), WalkAction(to_offset=2.0, speed=1.0)),))
    trace = simulate(m, 4.0)
    assert m.offset == pytest.approx(2.0, abs=EPS)
    assert trace.heading == [0.0] * len(trace.t)


@pytest.mark.parametrize(("trigger", "context", "fires_at"), [
    (EgoStationTrigger(60.0), lambda t: ctx(t, ego_s=50.0 + 10.0 * t), 1.0),
    (GapTrigger(25.0), lambda t: ctx(t, gap=40.0 - 10.0 * t), 1.5),
])
def test_walk_fires_on_ego_station_and_gap_triggers(
    trigger: Trigger, context: Callable[[float], TriggerContext], fires_at: float
) -> None:
    m = walker((trigger, WalkAction(to_offset=0.0, speed=WALK)))
    trace = simulate(m, 3.0, context)
    ((t, index),) = trace.started
    assert index == 0 and t == pytest.approx(fires_at, abs=DT + EPS)
    i = trace.t.index(t)
    assert trace.offset[i - 1] == FROM < trace.offset[i]


# ---------------------------------------------------------------------------------------
# In the world: bodies and ground truth
# ---------------------------------------------------------------------------------------

SCENARIO = """\
format: avsim/1
name: crossing
duration: 30
road:
  lanes: 2
  lane_width: 3.5
  speed_limit_kph: 50
  segments:
    - straight: 60
    - arc: {radius: 60, angle_deg: 60}
    - straight: 100
ego: {s: 10, speed_kph: 0, set_speed_kph: 40}
actors:
  - id: walker
    type: pedestrian
    s: 40
    offset: -6.0
    actions:
      - trigger: {time: 1.0}
        walk: {to_offset: 9.0, speed_kph: 5}
  - id: on_the_bend
    type: pedestrian
    lane: 1
    s: 90
    offset: 5.0
    actions:
      - trigger: {ego_s: 9}
        walk: {to_offset: -6, speed_kph: 7.2}
  - id: stroller
    type: pedestrian
    s: 20
    offset: -5.0
    speed_kph: 4
  - id: parked
    type: car
    lane: 1
    s: 30
"""


def write(tmp_path: Path, text: str = SCENARIO) -> Path:
    path = tmp_path / "crossing.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_pedestrians_and_walks_load(tmp_path: Path) -> None:
    assert "actors.*.type=pedestrian" not in scenario_module.UNSUPPORTED
    assert "actors.*.actions.*.walk" not in scenario_module.UNSUPPORTED
    spec = load_scenario(write(tmp_path)).world
    walker_, bend, stroller, parked = spec.actors
    assert (walker_.type, walker_.lane, walker_.s, walker_.offset, walker_.speed) == (
        ActorType.PEDESTRIAN, 0, 40.0, -6.0, 0.0)
    assert walker_.actions[0].trigger == TimeTrigger(1.0)
    assert walker_.actions[0].action == WalkAction(to_offset=9.0, speed=5 * KPH)
    assert (bend.lane, bend.offset) == (1, 5.0)
    assert bend.actions[0].trigger == EgoStationTrigger(9.0)
    assert bend.actions[0].action == WalkAction(to_offset=-6.0, speed=7.2 * KPH)
    assert stroller.speed == pytest.approx(4 * KPH) and not stroller.actions
    assert parked.type is ActorType.CAR


def test_walk_speed_must_be_positive(tmp_path: Path) -> None:
    path = write(tmp_path, SCENARIO.replace("speed_kph: 7.2", "speed_kph: 0"))
    with pytest.raises(ScenarioError) as raised:
        load_scenario(path)
    assert raised.value.key == "actors.1.actions.0.walk.speed_kph"


@dataclass
class WorldTrace:
    t: list[float] = field(default_factory=list)  # [s]
    poses: list[ActorPoses] = field(default_factory=list)
    bodies: list[list[tuple[tuple[float, ...], tuple[float, ...]]]] = field(default_factory=list)
    started: list[tuple[float, str, int]] = field(default_factory=list)
    phases: list[list[float]] = field(default_factory=list)  # [-] each walker's gait phase


@pytest.fixture(scope="module")
def world_run(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[World, WorldTrace]]:
    """The scenario for 14 s, the ego held by its brakes; poses sampled every 0.1 s."""
    spec = load_scenario(write(tmp_path_factory.mktemp("walk"))).world
    w = World(spec)
    trace = WorldTrace()
    try:
        for _ in range(14 * 240):
            w.ego.apply(0.0, 0.0, 2000.0)
            w.step()
            if w.clock.step % TRIGGER_RATE.every == 0:  # started_actions: at the last check
                trace.started += [(w.t, name, i) for name, i in w.started_actions]
            if w.clock.step % 24 == 0:
                trace.t.append(w.t)
                trace.poses.append(w.actors.poses)
                trace.bodies.append([w.client.getBasePositionAndOrientation(b)
                                     for b in w.actors.bodies])
                trace.phases.append(list(w.actors.phases))
        yield w, trace
    finally:
        w.close()


def test_world_fires_the_walks(world_run: tuple[World, WorldTrace]) -> None:
    _, trace = world_run
    # the bend walker's ego_s trigger holds at once (the ego stands at s = 10 > 9): first
    # trigger check at 40 Hz
    assert [(name, i) for _, name, i in trace.started] == [("on_the_bend", 0), ("walker", 0)]
    assert trace.started[0][0] == pytest.approx(1 / 40)
    assert trace.started[1][0] == pytest.approx(1.0)


def test_pedestrian_truth_while_crossing(world_run: tuple[World, WorldTrace]) -> None:
    _, trace = world_run
    first = trace.poses[0]
    assert first.kinds[:3] == (ActorType.PEDESTRIAN,) * 3
    np.testing.assert_allclose(first.half_sizes[0], [0.25, 0.3, 0.875])
    full_speed = 1.0 + WALK / LATERAL_ACCEL + 0.1  # [s]
    end = 1.0 + walk_time(15.0, WALK)  # [s]
    for t, p in zip(trace.t, trace.poses, strict=True):
        assert p.stations[0] == pytest.approx(40.0, abs=1e-9)  # straight across the road
        assert p.centres[0, 2] == pytest.approx(0.875)  # standing on the ground
        if t < 1.0:
            assert p.offsets[0] == -6.0 and p.speeds[0] == 0.0 and p.yaws[0] == 0.0
        elif full_speed <= t <= end - 1.0:  # walking, turned to face across
            assert p.speeds[0] == pytest.approx(WALK)
            assert p.yaws[0] == pytest.approx(HALF_PI)  # the road heads +x here
            assert p.offsets[0] == pytest.approx(
                -6.0 + WALK * (t - 1.0) - 0.5 * WALK**2 / LATERAL_ACCEL, abs=0.02)
            assert p.accels[0] == pytest.approx(0.0, abs=ACCEL_TOL)
            np.testing.assert_allclose(p.centres[0, :2], [40.0, p.offsets[0]], atol=1e-9)
        elif t > end + 0.1:  # arrived: stands facing across
            assert p.offsets[0] == pytest.approx(9.0, abs=1e-6)
            assert p.speeds[0] == 0.0 and p.accels[0] == 0.0
            assert p.yaws[0] == pytest.approx(HALF_PI)
    speeds = [p.speeds[0] for p in trace.poses]
    assert max(speeds) == pytest.approx(WALK)


def test_bodies_are_where_the_truth_says(world_run: tuple[World, WorldTrace]) -> None:
    """A box's origin is its centre; a walker's base is at its hips, `base_x` ahead of its
    body frame (on the ground under the centre) and `base_height` above."""
    w, trace = world_run
    for p, bodies, phases in zip(trace.poses, trace.bodies, trace.phases, strict=True):
        for i, (position, quat) in enumerate(bodies):
            expected = p.centres[i]
            walker = w.actors.walkers[i]
            if walker is not None:
                pose = walker_pose(walker.height, phases[i], walker.width, walker.amplitude)
                expected = [expected[0] + pose.base_x * math.cos(p.yaws[i]),
                            expected[1] + pose.base_x * math.sin(p.yaws[i]), pose.base_height]
            np.testing.assert_allclose(position, expected, atol=1e-6)
            yaw = 2.0 * math.atan2(quat[2], quat[3])
            assert math.remainder(yaw - p.yaws[i], 2 * math.pi) == pytest.approx(0.0, abs=1e-6)


def test_walk_on_a_bend_and_a_stroll(world_run: tuple[World, WorldTrace]) -> None:
    w, trace = world_run
    p = trace.poses[-1]
    # on the arc (it starts at s = 60 and turns left), from lane 1's centre + 5 to lane 1 - 6
    heading = float(w.road.line.heading(np.array([90.0]))[0])
    assert p.stations[1] == pytest.approx(90.0, abs=1e-9)
    assert p.offsets[1] == pytest.approx(LANE_WIDTH - 6.0, abs=1e-6)
    assert math.remainder(p.yaws[1] - (heading - HALF_PI), 2 * math.pi) == \
        pytest.approx(0.0, abs=1e-6)  # walked to the right of the route: faces right
    # a walking speed along the lane: station rate 4 km/h, facing along
    assert p.stations[2] == pytest.approx(20.0 + 4 * KPH * trace.t[-1], abs=1e-6)
    assert p.speeds[2] == pytest.approx(4 * KPH) and p.yaws[2] == pytest.approx(0.0)
    assert p.offsets[2] == -5.0
