"""A flat tyre changes the car physically (`world.ego.body.EgoBody.puncture`), and the scenario's
`flat_tire` event fires it (`world.ego.events`, the world's trigger checks).

The car runs on an empty straight road (the ground is an infinite plane, so a fixed steering
angle drives a circle), driven through its joints at the control rate like the runner does
(`apply` every 6 physics steps), with and without a puncture at t = 1 s. Measured:
the flat wheel spins r / r_flat faster, its corner sinks and the body rolls and pitches
toward it, the same drive torque no longer holds the speed; the car still accelerates,
steers on the Ackermann radius, brakes and holds. (The flat's drag is a yaw moment, but the
simulated tyres take no slip angle, so it does not turn the car: see `world.ego.body`.)
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray

from avsim.scenario.load import load_scenario
from vehicle_urdf import WHEELS
from world.core.rates import PHYSICS_RATE, TRIGGER_RATE
from world.ego.events import EgoEvents
from world.frames import Wheel
from world.spec import (
    AcceleratorOverride,
    AfterTrigger,
    EgoSpec,
    EgoStationTrigger,
    EventSpec,
    FlatTire,
    RoadSpec,
    SegmentSpec,
    TimeTrigger,
    WorldSpec,
)
from world.world import World

KPH = 1 / 3.6  # [m/s] per [km/h]
TICK = TRIGGER_RATE.every  # [steps] the runner's control tick (40 Hz)
HOLD_50 = 86.0  # [N m] total drive torque that holds the intact car at 50 km/h (measured)
T_FLAT = 1.0  # [s] when the tyre is punctured


def _spec(speed: float, events: tuple[EventSpec, ...] = ()) -> WorldSpec:
    road = RoadSpec(
        segments=(SegmentSpec(length=3000.0, curvature=0.0, lanes=2, oncoming_lanes=0,
                              lane_width=3.5, shoulder=2.5),),
        speed_limit=30.0,
    )
    return WorldSpec(road=road, ego=EgoSpec(lane=0, s=20.0, speed=speed, max_speed=30.0),
                     seed=0, events=events)


Command = Callable[[float, float], tuple[float, float, float]]  # (t, speed) -> apply's args


@dataclass
class Drive:
    """Samples every control tick after the first 0.5 s (the spawn settles)."""

    t: NDArray[np.float64]  # [s]
    speed: NDArray[np.float64]  # [m/s] forward
    yaw: NDArray[np.float64]  # [rad]
    yaw_rate: NDArray[np.float64]  # [rad/s]
    roll: NDArray[np.float64]  # [rad] + left side up
    pitch: NDArray[np.float64]  # [rad] + nose down
    spin: NDArray[np.float64]  # [rad/s] (N, 4) wheel spin, WHEELS order
    corner_z: NDArray[np.float64]  # [m] (N, 4) wheel centre heights
    drive: NDArray[np.float64]  # [N m] drive torque applied


def _drive(flat: str | None, seconds: float, command: Command, speed: float = 50 * KPH
           ) -> Drive:
    world = World(_spec(speed))
    ego, c = world.ego, world.client
    rows: list[list[float]] = []
    try:
        for step in range(round(seconds * PHYSICS_RATE)):
            if step % TICK == 0:
                truth = world.ego_truth
                ego.apply(*command(world.t, truth.speed))
                if world.t >= 0.5:
                    roll, pitch, _ = c.getEulerFromQuaternion(truth.quaternion.tolist())
                    heights = [c.getLinkState(ego.body, j)[0][2] for j in ego.wheel_joints]
                    rows.append([world.t, truth.speed, truth.yaw, truth.yaw_rate, roll, pitch,
                                 *truth.wheel_spin, *heights, ego.drive_torque])
            world.step()
            if flat is not None and step == round(T_FLAT * PHYSICS_RATE):
                ego.puncture(flat, world.t)
            if step % TICK == TICK - 1:
                ego.update_tyres(world.t)  # as the world's trigger checks do
    finally:
        world.close()
    a = np.array(rows)
    return Drive(a[:, 0], a[:, 1], a[:, 2], a[:, 3], a[:, 4], a[:, 5], a[:, 6:10],
                 a[:, 10:14], a[:, 14])


def _fixed(torque: float, steering: float = 0.0) -> Command:
    return lambda t, v: (steering, torque, 0.0)


def _hold(v_set: float) -> Command:
    """A proportional speed hold on the true speed (test scaffolding, not the stack)."""
    return lambda t, v: (0.0, HOLD_50 + 1500.0 * 0.33 * 2.0 * (v_set - v), 0.0)


def _after(d: Drive, t: float) -> NDArray[np.bool_]:
    return d.t >= t


# ---------------------------------------------------------------------------------------
# The physics
# ---------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def intact() -> Drive:
    return _drive(None, 5.0, _fixed(HOLD_50))


@pytest.fixture(scope="module", params=["rear_left", "front_right"])
def flat(request: pytest.FixtureRequest) -> tuple[str, Drive]:
    return request.param, _drive(request.param, 5.0, _fixed(HOLD_50))


def test_the_flat_wheel_rolls_on_the_flat_radius(flat: tuple[str, Drive]) -> None:
    wheel, d = flat
    i = WHEELS.index(wheel)
    settled = _after(d, T_FLAT + 1.5)
    others = np.delete(d.spin[settled], i, axis=1)
    ratio = d.spin[settled, i] / others.mean(axis=1)
    assert ratio == pytest.approx(0.33 / 0.31, rel=0.002)  # rolling radius 0.33 -> 0.31 m
    assert np.ptp(others, axis=1).max() < 0.002 * others.max()  # the others roll alike
    before = (d.t < T_FLAT) & _after(d, 0.6)
    assert np.abs(d.spin[before, i] / d.spin[before].mean(axis=1) - 1).max() < 1e-3
    # it deflates over ~1 s: the rolling radius changes when the rim takes over (~0.25 s)
    changed = d.t[d.spin[:, i] / np.delete(d.spin, i, axis=1).mean(axis=1) > 1.03][0]
    assert T_FLAT + 0.2 < changed < T_FLAT + 0.4


def test_the_flat_corner_sinks_and_the_body_leans_to_it(flat: tuple[str, Drive],
                                                        intact: Drive) -> None:
    wheel, d = flat
    i = WHEELS.index(wheel)
    settled = _after(d, T_FLAT + 1.5)
    drop = intact.corner_z[settled, i].mean() - d.corner_z[settled, i].mean()  # [m]
    assert 0.015 < drop < 0.03  # the wheel centre: ~2 cm (no suspension: see world.ego)
    left, front = wheel.endswith("left"), wheel.startswith("front")
    roll = math.degrees(d.roll[settled].mean() - intact.roll[settled].mean())
    pitch = math.degrees(d.pitch[settled].mean() - intact.pitch[settled].mean())
    assert 0.4 < abs(roll) < 0.8 and (roll < 0) == left  # the flat side down
    assert 0.15 < abs(pitch) < 0.4 and (pitch > 0) == front  # the flat end down
    # the other corners stay within a few mm
    others = np.delete(d.corner_z[settled] - intact.corner_z[settled], i, axis=1)
    assert np.abs(others).max() < 0.012


def test_the_same_torque_no_longer_holds_the_speed(flat: tuple[str, Drive],
                                                   intact: Drive) -> None:
    _, d = flat
    t0, t1 = T_FLAT + 1.5, 5.0 - 1 / 40
    window = _after(d, t0)
    decel = -np.polyfit(d.t[window], d.speed[window], 1)[0]  # [m/s^2]
    intact_decel = -np.polyfit(intact.t[window], intact.speed[window], 1)[0]
    assert abs(intact_decel) < 0.005
    # the flat's extra rolling resistance, (0.15 - 0.012) * ~1.75 kN, over the car's mass
    assert 0.12 < decel < 0.2
    assert d.speed[-1] < intact.speed[-1] - 0.12 * (t1 - t0)


def test_holding_the_speed_on_a_flat_takes_more_drive() -> None:
    d = _drive("rear_left", 4.0, _hold(50 * KPH))
    held = _after(d, 3.0)
    assert d.speed[held] == pytest.approx(50 * KPH, abs=0.1)
    before = (d.t < T_FLAT) & _after(d, 0.6)
    # intact ~86 N m (roll 177 N + drag 81 N at 0.33 m); flat: + ~240 N at the rim, ~160
    assert d.drive[before].mean() == pytest.approx(HOLD_50, rel=0.05)
    assert d.drive[held].mean() > 1.6 * d.drive[before].mean()


def test_the_car_still_drives_steers_brakes_and_holds_on_a_flat() -> None:
    delta = 0.1  # [rad] a left turn, R = 2.7 / tan(0.1) = 26.9 m

    def command(t: float, v: float) -> tuple[float, float, float]:
        if t < 4.0:  # speed up from 30 km/h
            return 0.0, 600.0, 0.0
        if t < 9.0:  # turn on the flat
            return delta, 120.0 + 1500.0 * 0.33 * (10.0 - v), 0.0
        return 0.0, 0.0, 1500.0 * 4.0 * 0.33  # ~4 m/s^2 of brake

    d = _drive("rear_left", 13.0, command, speed=30 * KPH)
    accel = np.polyfit(d.t[(d.t > 2.5) & (d.t < 3.5)], d.speed[(d.t > 2.5) & (d.t < 3.5)], 1)[0]
    assert accel == pytest.approx(600.0 / 0.33 / 1500.0 - 0.3, abs=0.25)  # ~1.2 m/s^2 - losses
    turning = (d.t > 6.0) & (d.t < 9.0)
    curvature = d.yaw_rate[turning] / d.speed[turning]  # [1/m]
    assert curvature.mean() == pytest.approx(math.tan(delta) / 2.7, rel=0.05)
    stopped = d.t > 12.0
    assert np.abs(d.speed[stopped]).max() < 0.01
    assert np.abs(np.diff(d.yaw[stopped])).max() < 1e-6  # held, not creeping round


def test_an_intact_car_does_not_touch_its_rims() -> None:
    """The flat-tyre spheres sit 2 cm inside the tyres and carry nothing until a puncture,
    even with the front tyres loaded by hard braking."""
    world = World(_spec(50 * KPH))
    ego, c = world.ego, world.client
    load = 0.0
    try:
        ego.apply(0.0, 0.0, 1500.0 * 7.0 * 0.33)
        for _ in range(PHYSICS_RATE * 2):
            world.step()
            load = max([load, *(p[9] for rim in ego.rim_links
                                for p in c.getContactPoints(bodyA=ego.body, linkIndexA=rim))])
        assert world.ego_truth.speed < 1.0
        assert ego.flat_wheels == ()
    finally:
        world.close()
    assert load == 0.0


def test_a_second_puncture_of_the_same_tyre_changes_nothing() -> None:
    world = World(_spec(50 * KPH))
    try:
        world.ego.puncture("rear_left", 0.0)
        world.ego.puncture("rear_left", 0.5)
        world.ego.puncture("front_right", 0.5)
        assert world.ego.flat_wheels == ("front_right", "rear_left")
        with pytest.raises(ValueError):
            world.ego.puncture("spare", 0.5)
    finally:
        world.close()


# ---------------------------------------------------------------------------------------
# The event: triggers (pure), then in the world
# ---------------------------------------------------------------------------------------


def _flat(trigger: TimeTrigger | EgoStationTrigger | AfterTrigger, wheel: Wheel) -> EventSpec:
    return EventSpec(trigger, FlatTire(wheel))


def test_a_flat_tire_fires_once_at_its_trigger_and_ends_as_it_fires() -> None:
    events = EgoEvents((
        _flat(TimeTrigger(0.5), Wheel.REAR_LEFT),
        EventSpec(AfterTrigger(0, 0.25), AcceleratorOverride(pedal=0.5, duration=0.5)),
        _flat(EgoStationTrigger(30.0), Wheel.FRONT_RIGHT),
    ))
    started, flats = [], []
    for k in range(1, 61):  # checks at 40 Hz for 1.5 s; the ego passes 30 m at 0.625 s
        t = k / 40
        started.append(events.update(t, 20.0 + 16.0 * t))
        flats.append(events.started_flats)
    assert events.fired_at == (0.5, 0.75, 0.625)
    assert events.ended_at == (0.5, 1.25, 0.625)  # the override ran its 0.5 s
    assert [s for s in started if s] == [(0,), (2,), (1,)]
    assert [f for f in flats if f] == [(Wheel.REAR_LEFT,), (Wheel.FRONT_RIGHT,)]
    assert events.flat_tires == (Wheel.REAR_LEFT, Wheel.FRONT_RIGHT)
    assert events.pedal == 0.0


def test_a_flat_tire_does_not_release_a_held_pedal() -> None:
    events = EgoEvents((
        EventSpec(TimeTrigger(0.0), AcceleratorOverride(pedal=0.7, duration=2.0)),
        _flat(TimeTrigger(1.0), Wheel.REAR_RIGHT),
    ))
    pedals = []
    for k in range(1, 91):  # the override fires at the first check, 0.025 s
        events.update(k / 40, 0.0)
        pedals.append(events.pedal)
    assert pedals == [0.7 if k <= 80 else 0.0 for k in range(1, 91)]
    assert events.ended_at[0] == pytest.approx(2.025)
    assert events.ended_at[1] == 1.0


FLAT_SCENARIO = """\
format: avsim/1
name: flat
duration: 3
seed: 2
road:
  lanes: 1
  speed_limit_kph: 50
  segments:
    - straight: 300
ego: {lane: 0, s: 20, speed_kph: 50, set_speed_kph: 50}
events:
  - trigger: {time: 1}
    flat_tire: {wheel: rear_left}
"""


@dataclass
class ScenarioRun:
    poses: list[tuple[float, ...]]  # per control tick: position, quaternion, wheel spins
    flats: list[tuple[str, ...]]  # per control tick: the ego's punctured tyres
    fired_at: tuple[float | None, ...]
    ended_at: tuple[float | None, ...]


def _run_scenario(spec: WorldSpec, duration: float) -> ScenarioRun:
    """Hold 86 N m (50 km/h) for `duration` [s], reading the ego every tick."""
    world = World(spec)
    poses = []
    flats_at = []
    try:
        for step in range(round(duration * PHYSICS_RATE)):
            if step % TICK == 0:
                world.ego.apply(0.0, HOLD_50, 0.0)
            world.step()
            if step % TICK == TICK - 1:
                truth = world.ego_truth
                poses.append((*truth.position.tolist(), *truth.quaternion.tolist(),
                              *truth.wheel_spin.tolist()))
                flats_at.append(world.ego.flat_wheels)
        return ScenarioRun(poses, flats_at, world.event_fired_at, world.event_ended_at)
    finally:
        world.close()


def test_the_flat_tire_event_of_a_scenario_file_deflates_the_tyre(tmp_path: Path) -> None:
    path = tmp_path / "flat.yaml"
    path.write_text(FLAT_SCENARIO, encoding="utf-8")
    scenario = load_scenario(path)
    spec, duration = scenario.world, scenario.duration
    assert spec.events == (_flat(TimeTrigger(1.0), Wheel.REAR_LEFT),)
    run = _run_scenario(spec, duration)
    assert run.fired_at == (1.0,) and run.ended_at == (1.0,)
    check = round(1.0 * TRIGGER_RATE.hz) - 1  # the tick of the check at 1 s
    assert run.flats[check - 1] == () and run.flats[check] == ("rear_left",)
    spin = np.array(run.poses)[:, 7:]
    assert spin[-1, 2] / spin[-1, 3] == pytest.approx(0.33 / 0.31, rel=0.002)
    assert _run_scenario(spec, duration).poses == run.poses  # deterministic, bit for bit
    without = _run_scenario(dataclasses.replace(spec, events=()), duration)
    assert without.flats[-1] == ()
    assert without.poses[:check + 1] == run.poses[:check + 1]  # the same up to the puncture
    assert without.poses[-1] != run.poses[-1]
