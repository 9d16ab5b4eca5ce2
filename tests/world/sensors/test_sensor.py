"""Every sensor of the car implements the one `Sensor` interface: its name, rate and latency
are its entry in the rates table, and a capture is a `Reading` of its frame type stamped
with the capture time (ground truth beside it only where there is some)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from avsim.scenario.load import load_scenario
from world.frames import CameraFrame, GnssFix, LidarScan, Odometry
from world.sensors.camera import CameraSensor
from world.sensors.gnss import GnssSensor
from world.sensors.lidar import LidarSensor, LidarTruth
from world.sensors.odometry import OdometrySensor
from world.sensors.sensor import Reading, Sensor
from world.sensors.setup import Profile, sensor_setup, sensor_timings
from world.world import World

FRAME_TYPES = {CameraSensor: CameraFrame, LidarSensor: LidarScan, GnssSensor: GnssFix,
               OdometrySensor: Odometry}


@pytest.fixture(scope="module")
def world() -> Iterator[World]:
    """normal_driving with every sensor of the `default` profile in one client."""
    w = World(load_scenario("normal_driving").world, sensor_setup(Profile.DEFAULT))
    for _ in range(48):
        w.step()
    yield w
    w.close()


def test_the_rig_holds_every_sensor_of_the_table(world: World) -> None:
    table = dict(sensor_timings(sensor_setup(Profile.DEFAULT)))
    assert sorted(world.rig.names) == sorted(table)
    kinds = {name: type(world.rig.sensor(name)) for name in world.rig.names}
    assert kinds == {"front": CameraSensor, "left": CameraSensor, "right": CameraSensor,
                     "lidar": LidarSensor, "gnss": GnssSensor, "odometry": OdometrySensor}


@pytest.mark.parametrize("name", ["front", "left", "right", "lidar", "gnss", "odometry"])
def test_each_sensor_implements_the_interface(world: World, name: str) -> None:
    sensor = world.rig.sensor(name)
    assert isinstance(sensor, Sensor)
    timing = dict(sensor_timings(sensor_setup(Profile.DEFAULT)))[name]
    assert sensor.name == name
    assert sensor.rate is timing.rate
    assert sensor.latency == timing.latency
    reading = sensor.capture(world.t, world.ego_truth)
    assert isinstance(reading, Reading)
    assert reading.sensor == name
    assert isinstance(reading.frame, FRAME_TYPES[type(sensor)])
    assert reading.frame.t == world.t
    if isinstance(sensor, LidarSensor):
        assert isinstance(reading.truth, LidarTruth)
        assert isinstance(reading.frame, LidarScan)
        assert len(reading.truth.actor) == len(reading.frame.points) > 0
    else:
        assert reading.truth is None


def test_noise_comes_from_each_sensors_own_generator(world: World) -> None:
    """Two captures at one instant differ by their noise; capturing one sensor more often
    leaves another's stream untouched."""
    truth = world.ego_truth
    (a, b) = world.rig.capture(["gnss", "gnss"], world.t, truth)
    assert isinstance(a.frame, GnssFix) and isinstance(b.frame, GnssFix)
    assert a.frame.x != b.frame.x
    spec = load_scenario("normal_driving").world
    fixes = []
    for extra_odometry in (0, 3):
        w = World(spec)
        try:
            w.rig.capture(["odometry"] * extra_odometry, w.t, w.ego_truth)
            fixes.append(w.rig.capture(["gnss"], w.t, w.ego_truth)[0].frame)
        finally:
            w.close()
    assert fixes[0] == fixes[1]


def test_capturing_an_unknown_sensor_names_the_rig(world: World) -> None:
    with pytest.raises(KeyError, match="front, left, right, lidar, gnss, odometry"):
        world.rig.capture(["radar"], world.t, world.ego_truth)
    assert "radar" not in world.rig and "front" in world.rig
