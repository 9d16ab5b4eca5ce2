"""Ego events (`world.ego.events`): the accelerator override holds the pedal SENSOR.

The car is drive-by-wire: the world only holds the pedal position (what the odometry's
pedal sensor reads) from the trigger for `duration` seconds; it adds no torque. The stack
arbitrates the pedal (its speed limiter), elsewhere. The first tests are pure (checks at the
world's 40 Hz trigger rate, t = k / 40); the rest build small worlds, one scenario loaded
from YAML, run with and without its events.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from avsim.scenario.load import ScenarioError, load_scenario
from world.core.rates import PHYSICS_RATE, TRIGGER_RATE
from world.ego.events import EgoEvents
from world.spec import (
    AcceleratorOverride,
    AfterTrigger,
    CameraBlackout,
    EgoStationTrigger,
    EventSpec,
    GapTrigger,
    GnssJump,
    LidarOutage,
    TimeTrigger,
    Trigger,
    WorldSpec,
)
from world.world import World

CHECK_HZ = TRIGGER_RATE.hz  # [Hz] trigger checks, one every TRIGGER_RATE.every physics steps


def override(trigger: Trigger, pedal: float, duration: float) -> EventSpec:
    return EventSpec(trigger, AcceleratorOverride(pedal=pedal, duration=duration))


def check_times(seconds: float) -> list[float]:
    """[s] the world's trigger checks: t = k / 40 for k = 1, 2, ..."""
    return [k / CHECK_HZ for k in range(1, round(seconds * CHECK_HZ) + 1)]


def pedals(events: EgoEvents, times: list[float], stations: list[float] | None = None
           ) -> list[float]:
    """The pedal after each check."""
    out = []
    for k, t in enumerate(times):
        events.update(t, -1.0 if stations is None else stations[k])
        out.append(events.pedal)
    return out


# ---------------------------------------------------------------------------------------
# Triggers and the pedal (pure)
# ---------------------------------------------------------------------------------------


def test_time_trigger_holds_the_pedal_for_its_duration_then_releases() -> None:
    events = EgoEvents((override(TimeTrigger(0.5), pedal=0.6, duration=1.0),))
    times = check_times(3.0)
    got = pedals(events, times)
    assert got == [0.6 if 0.5 <= t < 1.5 else 0.0 for t in times]
    assert got.count(0.6) == 1.0 * CHECK_HZ  # held for exactly `duration`
    assert events.fired_at == (0.5,)
    assert events.ended_at == (1.5,)


def test_time_trigger_off_the_check_grid_fires_at_the_next_check() -> None:
    events = EgoEvents((override(TimeTrigger(0.51), pedal=1.0, duration=0.2),))
    got = pedals(events, check_times(1.0))
    assert events.fired_at == (0.525,)  # the first check at or after 0.51 s
    ended = events.ended_at[0]
    assert ended == pytest.approx(0.725)  # 0.525 + 0.2: a float sum, released on its check
    assert got.count(1.0) == round(0.2 * CHECK_HZ)


def test_started_reports_each_event_once_at_its_check() -> None:
    events = EgoEvents((override(TimeTrigger(0.1), 1.0, 0.1),))
    started = [(t, events.update(t, 0.0)) for t in check_times(1.0)]
    assert [(t, s) for t, s in started if s] == [(0.1, (0,))]
    assert events.started == ()  # as of the last check


def test_ego_station_trigger_fires_when_the_ego_reaches_it() -> None:
    events = EgoEvents((override(EgoStationTrigger(100.0), pedal=0.4, duration=0.1),))
    times = check_times(0.2)
    stations = [95.0, 99.99, 100.0, 101.0, 102.0, 103.0, 104.0, 105.0]
    got = pedals(events, times, stations)
    assert got == [0.0, 0.0, 0.4, 0.4, 0.4, 0.4, 0.0, 0.0]
    assert events.fired_at == (times[2],)
    assert events.ended_at == (times[6],)


def test_after_chain_fires_delay_after_the_previous_override_ended() -> None:
    events = EgoEvents((
        override(TimeTrigger(0.5), pedal=0.3, duration=1.0),  # 0.5 .. 1.5
        override(AfterTrigger(index=0, delay=0.25), pedal=0.8, duration=0.5),  # 1.75 .. 2.25
        override(AfterTrigger(index=1, delay=0.0), pedal=1.0, duration=0.25),  # 2.25 .. 2.5
    ))
    times = check_times(3.0)
    got = pedals(events, times)

    def expected(t: float) -> float:
        if 0.5 <= t < 1.5:
            return 0.3
        if 1.75 <= t < 2.25:
            return 0.8
        if 2.25 <= t < 2.5:
            return 1.0  # delay 0: fires at the very check the previous one ended
        return 0.0

    assert got == [expected(t) for t in times]
    assert events.fired_at == (0.5, 1.75, 2.25)
    assert events.ended_at == (1.5, 2.25, 2.5)


def test_after_waits_for_an_override_that_has_not_ended() -> None:
    events = EgoEvents((
        override(TimeTrigger(10.0), pedal=1.0, duration=1.0),  # never fires in this run
        override(AfterTrigger(index=0, delay=0.0), pedal=0.5, duration=1.0),
    ))
    assert set(pedals(events, check_times(2.0))) == {0.0}
    assert events.fired_at == (None, None)


def test_a_later_override_replaces_a_running_one_which_ends() -> None:
    events = EgoEvents((
        override(TimeTrigger(0.0), pedal=0.5, duration=10.0),
        override(TimeTrigger(1.0), pedal=1.0, duration=1.0),
    ))
    times = check_times(4.0)
    got = pedals(events, times)
    assert got == [0.5 if t < 1.0 else 1.0 if t < 2.0 else 0.0 for t in times]
    assert events.ended_at == (1.0, 2.0)  # the first one does not come back


def test_sensor_faults_run_for_their_duration_beside_an_override() -> None:
    events = EgoEvents((
        EventSpec(TimeTrigger(0.5), CameraBlackout("front", 1.0)),
        EventSpec(TimeTrigger(1.0), LidarOutage(0.5)),
        override(TimeTrigger(1.0), 0.4, 2.0),
        EventSpec(AfterTrigger(1, 0.0), GnssJump((5.0, 0.0), 0.25)),
    ))
    running = {}
    for t in check_times(3.0):
        events.update(t, 0.0)
        running[t] = events.faults
    assert running[0.475] == ()
    assert running[0.5] == (CameraBlackout("front", 1.0),)
    assert running[1.0] == (CameraBlackout("front", 1.0), LidarOutage(0.5))
    assert events.pedal == 0.0  # released at 3.0
    assert running[1.475] == (CameraBlackout("front", 1.0), LidarOutage(0.5))
    assert running[1.5] == (GnssJump((5.0, 0.0), 0.25),)  # after the outage ended
    assert running[1.75] == ()
    assert events.fired_at == (0.5, 1.0, 1.0, 1.5)
    assert events.ended_at == (1.5, 1.5, 3.0, 1.75)


@pytest.mark.parametrize(
    ("event", "message"),
    [
        (override(GapTrigger(10.0), 1.0, 1.0), "events.0.trigger.gap: only for actors"),
        (override(AfterTrigger(0, 0.0), 1.0, 1.0), "events.0.trigger.after: must refer"),
    ],
)
def test_what_the_world_cannot_do_is_refused(event: EventSpec, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        EgoEvents((event,))


# ---------------------------------------------------------------------------------------
# The loader
# ---------------------------------------------------------------------------------------

SCENARIO = """\
format: avsim/1
name: pedal
situation: external_disturbance
duration: 4
seed: 1
road:
  lanes: 2
  speed_limit_kph: 50
  segments:
    - straight: 300
ego: {lane: 0, s: 20, speed_kph: 36, set_speed_kph: 36}
events:
  - trigger: {time: 0.5}
    accelerator_override: {pedal: 0.7, duration: 1.0}
  - trigger: {ego_s: 42}
    accelerator_override: {pedal: 0.4, duration: 0.5}
  - trigger: {after: 1, delay: 0.25}
    accelerator_override: {pedal: 1.0, duration: 0.25}
"""


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "pedal.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_an_accelerator_override_loads(tmp_path: Path) -> None:
    loaded = load_scenario(_write(tmp_path, SCENARIO))
    assert loaded.world.events == (
        override(TimeTrigger(0.5), 0.7, 1.0),
        override(EgoStationTrigger(42.0), 0.4, 0.5),
        override(AfterTrigger(index=1, delay=0.25), 1.0, 0.25),
    )


def test_a_gap_trigger_on_an_event_is_a_load_error_naming_the_key(tmp_path: Path) -> None:
    path = _write(tmp_path, SCENARIO.replace("{ego_s: 42}", "{gap: 10}"))
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert info.value.key == "events.1.trigger.gap"
    assert str(info.value) == f"{path}: events.1.trigger.gap: only for actors (the gap to the ego)"


# ---------------------------------------------------------------------------------------
# In the world: the odometry's pedal sensor, and no force
# ---------------------------------------------------------------------------------------


@dataclass
class Run:
    """Per control tick (every TRIGGER_RATE.every steps, as the runner's 40 Hz tick)."""

    t: list[float]
    ego_s: list[float]  # [m] the station the triggers saw
    pedal: list[float]  # World.accelerator_pedal
    odo_pedal: list[float]  # Odometry.accelerator_pedal
    odo_spins: list[tuple[float, ...]]  # [rad/s] the (noisy) encoders
    speed: list[float]  # [m/s] true
    pose: list[tuple[float, ...]]  # true position and quaternion
    fired_at: tuple[float | None, ...]
    ended_at: tuple[float | None, ...]


def _drive(spec: WorldSpec, duration: float) -> Run:
    """Coast with zero commands (no steering, drive or brake) for `duration` [s]."""
    world = World(spec)
    run = Run([], [], [], [], [], [], [], (), ())
    try:
        world.ego.apply(0.0, 0.0, 0.0)
        for _ in range(round(duration * PHYSICS_RATE)):
            world.step()
            if world.clock.step % TRIGGER_RATE.every:
                continue
            truth = world.ego_truth
            odo = world.rig.capture(["odometry"], world.t, truth)[0].frame
            run.t.append(world.t)
            run.ego_s.append(world.ego_s)
            run.pedal.append(world.accelerator_pedal)
            run.odo_pedal.append(odo.accelerator_pedal)
            run.odo_spins.append(odo.wheel_speeds)
            run.speed.append(truth.speed)
            run.pose.append((*truth.position.tolist(), *truth.quaternion.tolist()))
        run.fired_at, run.ended_at = world.event_fired_at, world.event_ended_at
    finally:
        world.close()
    return run


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> tuple[Run, Run]:
    """The scenario with its events, and the same without them."""
    scenario = load_scenario(_write(tmp_path_factory.mktemp("pedal"), SCENARIO))
    spec, duration = scenario.world, scenario.duration
    return _drive(spec, duration), _drive(dataclasses.replace(spec, events=()), duration)


def test_the_pedal_follows_the_triggers_in_the_world(runs: tuple[Run, Run]) -> None:
    run, _ = runs
    t = np.array(run.t)
    reached = t[np.array(run.ego_s) >= 42.0][0]  # the first check with the ego at 42 m
    assert 1.0 < reached < 3.0  # coasting from 10 m/s: after the first override, in the run
    windows = [(0.5, 1.5, 0.7), (reached, reached + 0.5, 0.4),
               (reached + 0.5 + 0.25, reached + 0.5 + 0.25 + 0.25, 1.0)]  # [s] from, to; pedal
    assert run.fired_at == pytest.approx([start for start, _, _ in windows], abs=1e-9)
    assert run.ended_at == pytest.approx([end for _, end, _ in windows], abs=1e-9)

    def expected(tk: float) -> float:
        for start, end, pedal in windows:  # on the check grid, to float round-off
            if start - 1e-9 <= tk < end - 1e-9:
                return pedal
        return 0.0

    assert run.pedal == [expected(tk) for tk in run.t]


def test_the_odometry_carries_the_pedal(runs: tuple[Run, Run]) -> None:
    run, without = runs
    assert run.odo_pedal == run.pedal
    assert max(run.odo_pedal) == 1.0
    assert set(without.odo_pedal) == {0.0}
    assert without.fired_at == ()


def test_the_world_adds_no_force_for_the_pedal(runs: tuple[Run, Run]) -> None:
    """Stepped with zero commands, the car coasts exactly as it does without the events:
    same speeds, poses and encoder readings (the noise stream is untouched too)."""
    run, without = runs
    assert run.speed[0] > run.speed[-1] > 8.0  # it coasts (resistance), it is not parked
    assert run.speed == without.speed
    assert run.pose == without.pose
    assert run.odo_spins == without.odo_spins
