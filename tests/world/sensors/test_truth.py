"""The truth sensor (`world.sensors.truth`): only in privileged truth mode, at the control
rate, without the actors hidden from the sensors."""

from __future__ import annotations

from avsim.scenario.load import load_scenario
from world.frames import GroundTruth, SensorKind
from world.sensors.setup import sensor_specs, sensor_timings
from world.world import World


def test_the_truth_sensor_is_on_the_car_only_in_privileged_mode() -> None:
    assert "truth" not in dict(sensor_timings(None))
    assert all(s.kind is not SensorKind.TRUTH for s in sensor_specs(None))
    timing = dict(sensor_timings(None, privileged=True))["truth"]
    assert (timing.rate.hz, timing.latency) == (40, 0.0)
    assert sensor_specs(None, privileged=True)[-1].kind is SensorKind.TRUTH
    spec = load_scenario("cut_in_out").world
    assert "truth" not in World(spec).rig
    assert "truth" in World(spec, privileged=True).rig


def _ids(world: World) -> list[str]:
    frame = world.rig.capture(("truth",), world.t, world.ego_truth)[0].frame
    assert isinstance(frame, GroundTruth)
    return [o.id for o in frame.objects]


def test_an_actor_hidden_from_the_sensors_is_not_in_the_truth() -> None:
    world = World(load_scenario("cut_in_out").world, privileged=True)
    assert _ids(world) == ["cutter", "oncoming"]
    world.set_actor_visibility(0, cameras=False, lidar=True)  # graphics off, sensors on
    assert _ids(world) == ["cutter", "oncoming"]
    world.set_actor_visibility(0, cameras=False, lidar=False)  # hidden from the sensors
    assert _ids(world) == ["oncoming"]
    world.set_actor_visibility(0, cameras=True, lidar=True)
    assert _ids(world) == ["cutter", "oncoming"]
