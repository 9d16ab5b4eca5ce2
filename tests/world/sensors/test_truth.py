"""The truth sensor (`world.sensors.truth`): only in privileged truth mode, at the control
rate, without the actors hidden from the sensors."""

from __future__ import annotations

import numpy as np
import pytest

from avsim.scenario.load import load_scenario
from world.actors.actor_set import ActorPoses
from world.frames import GroundTruth, SensorKind
from world.sensors.setup import sensor_specs, sensor_timings
from world.sensors.truth import truth_objects
from world.spec import ActorType
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


def _poses(x: float, y: float, yaw: float, speed: float) -> ActorPoses:
    return ActorPoses(ids=("walker",), kinds=(ActorType.PEDESTRIAN,),
                      centres=np.array([[x, y, 0.9]]), yaws=np.array([yaw]),
                      half_sizes=np.array([[0.25, 0.3, 0.9]]), stations=np.array([x]),
                      offsets=np.array([y]), speeds=np.array([speed]),
                      accels=np.array([0.0]))


def test_an_objects_velocity_is_its_motion_over_ground_not_its_heading() -> None:
    """A walker facing along the road (yaw 0) but stepping sideways at 1.2 m/s: its first
    frame can only say its speed along its heading; from the second, its motion."""
    before: dict[str, tuple[float, float, float]] = {}
    (first,) = truth_objects(_poses(10.0, 2.0, 0.0, 1.2), (), 1.0, before)
    assert (first.vx, first.vy) == (1.2, 0.0)
    (second,) = truth_objects(_poses(10.0, 2.03, 0.0, 1.2), (), 1.025, before)
    assert (second.vx, second.vy) == pytest.approx((0.0, 1.2))
    (late,) = truth_objects(_poses(10.0, 2.5, 0.0, 1.2), (), 2.0, before)  # shown again
    assert (late.vx, late.vy) == (1.2, 0.0)
