"""The sensor schedule: which sensors capture at which physics step (GNSS and odometry
included), grouped by when they reach the stack, from the rates table; rates and latencies
that do not fit the control ticks are rejected."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from world.core.rates import CONTROL_RATE, PHYSICS_RATE, Rate, SensorTiming
from world.sensors.schedule import Due, SensorSchedule
from world.sensors.setup import Profile, sensor_setup, sensor_timings

CAMERAS_LIDAR = ("front", "left", "right", "lidar")
CAR = ("gnss", "odometry")


def schedule(profile: Profile | None = Profile.DEFAULT) -> SensorSchedule:
    setup = sensor_setup(profile) if profile is not None else None
    return SensorSchedule(sensor_timings(setup), CONTROL_RATE)


# Row by row: the `default` profile (front and LiDAR at 10 Hz, the sides at 2 Hz, frames
# delivered 24 steps = 0.1 s late), GNSS at 10 Hz and odometry at 40 Hz (delivered at once).
DEFAULT_ROWS = {
    0: (Due(0, 24, CAMERAS_LIDAR), Due(0, 0, CAR)),
    6: (Due(6, 6, ("odometry",)),),
    12: (Due(12, 12, ("odometry",)),),
    18: (Due(18, 18, ("odometry",)),),
    24: (Due(24, 48, ("front", "lidar")), Due(24, 24, CAR)),
    96: (Due(96, 120, ("front", "lidar")), Due(96, 96, CAR)),
    114: (Due(114, 114, ("odometry",)),),
    120: (Due(120, 144, CAMERAS_LIDAR), Due(120, 120, CAR)),
    240: (Due(240, 264, CAMERAS_LIDAR), Due(240, 240, CAR)),
}


@pytest.mark.parametrize(("step", "expected"), DEFAULT_ROWS.items(), ids=str)
def test_default_profile_step_by_step(step: int, expected: tuple[Due, ...]) -> None:
    assert schedule().due(step) == expected


def test_nothing_fires_between_control_ticks() -> None:
    s = schedule(Profile.PAPER)
    for step in range(2 * PHYSICS_RATE):
        if step % CONTROL_RATE.every:
            assert s.due(step) == (), step
        else:
            assert any("odometry" in due.sensors for due in s.due(step)), step


def test_due_time_is_the_clock_time() -> None:
    for step in (0, 24, 1234, 24_000):
        assert Due(step, step, ()).t == step / PHYSICS_RATE


def test_one_second_of_the_default_profile() -> None:
    s = schedule()
    counts = Counter(due.sensors for step in range(PHYSICS_RATE) for due in s.due(step))
    assert counts == {CAMERAS_LIDAR: 2, ("front", "lidar"): 8, CAR: 10, ("odometry",): 30}


@pytest.mark.parametrize("profile", [*Profile, None])
def test_each_sensor_fires_at_its_rate_and_is_delivered_after_its_latency(
        profile: Profile | None) -> None:
    s = schedule(profile)
    expected = {"gnss": (10, 0), "odometry": (40, 0)}  # Hz, latency [steps]
    if profile is not None:
        side = {Profile.FAST: None, Profile.DEFAULT: 2, Profile.PAPER: 10}[profile]
        expected |= {"front": (10, 24), "lidar": (10, 24)}
        if side is not None:
            expected |= {"left": (side, 24), "right": (side, 24)}
    assert set(s.names) == set(expected)
    seconds = 10
    fired: dict[str, list[int]] = {name: [] for name in s.names}
    for step in range(seconds * PHYSICS_RATE):
        for due in s.due(step):
            assert due.step == step
            for name in due.sensors:
                fired[name].append(step)
                assert due.deliver - step == expected[name][1], name
    for name, steps in fired.items():
        hz = expected[name][0]
        assert len(steps) == seconds * hz, name
        assert steps[0] == 0
        assert set(np.diff(steps).tolist()) == {PHYSICS_RATE // hz}, name


def test_a_due_lists_its_sensors_in_the_schedules_order() -> None:
    timing = SensorTiming(Rate("x", 10))
    s = SensorSchedule([("b", timing), ("a", timing), ("c", SensorTiming(Rate("y", 40)))],
                       CONTROL_RATE)
    assert s.names == ("b", "a", "c")
    assert s.due(0) == (Due(0, 0, ("b", "a", "c")),)
    assert s.due(6) == (Due(6, 6, ("c",)),)


def test_rates_and_latencies_that_do_not_fit_are_rejected() -> None:
    for hz in (7, 0, -10, 480):  # does not divide 240 Hz; no rate; faster than physics
        with pytest.raises(ValueError, match="must divide"):
            Rate("front", hz)
    with pytest.raises(ValueError, match="whole number of physics steps"):
        SensorTiming(Rate("front", 10), latency=0.001)
    with pytest.raises(ValueError, match="whole number of physics steps"):
        SensorTiming(Rate("front", 10), latency=-0.1)
    front = SensorTiming(Rate("front", 10), latency=0.1)
    # 16 Hz divides 240 Hz (15 steps) but is asked for on the 6-step control ticks
    with pytest.raises(ValueError, match="multiple"):
        SensorSchedule([("front", SensorTiming(Rate("front", 16)))], CONTROL_RATE)
    # a latency of 3 steps ends between two control ticks
    with pytest.raises(ValueError, match="multiple"):
        SensorSchedule([("front", SensorTiming(Rate("front", 10), latency=3 / 240))],
                       CONTROL_RATE)
    with pytest.raises(ValueError, match="unique"):
        SensorSchedule([("front", front), ("front", front)], CONTROL_RATE)
    # 20 Hz (12 steps) with the LiDAR's 24 and a 0.05 s latency: fine
    fast = SensorSchedule([("front", SensorTiming(Rate("front", 20), latency=0.05)),
                           ("lidar", front)], CONTROL_RATE)
    assert fast.due(12) == (Due(12, 24, ("front",)),)
    assert fast.due(24) == (Due(24, 36, ("front",)), Due(24, 48, ("lidar",)))


def test_keep_thins_a_sensors_captures_and_zero_silences_it() -> None:
    setup = sensor_setup(Profile.PAPER)
    thinned = SensorSchedule(sensor_timings(setup), CONTROL_RATE,
                             keep={"left": 4, "right": 0})
    full = SensorSchedule(sensor_timings(setup), CONTROL_RATE)
    steps = range(0, 2 * PHYSICS_RATE, CONTROL_RATE.every)

    def captures(s: SensorSchedule, name: str) -> list[int]:
        return [step for step in steps for due in s.due(step) if name in due.sensors]

    assert captures(full, "left") == list(range(0, 2 * PHYSICS_RATE, 24))  # 10 Hz
    assert captures(thinned, "left") == [0, 96, 192, 288, 384]  # every 4th: 2.5 Hz
    assert captures(thinned, "right") == []
    for name in ("front", "lidar", "gnss", "odometry"):
        assert captures(thinned, name) == captures(full, name)


@pytest.mark.parametrize("keep", [{"rear": 1}, {"left": -1}])
def test_a_bad_keep_is_rejected(keep: dict[str, int]) -> None:
    with pytest.raises(ValueError, match="keep"):
        SensorSchedule(sensor_timings(sensor_setup(Profile.DEFAULT)), CONTROL_RATE, keep)
