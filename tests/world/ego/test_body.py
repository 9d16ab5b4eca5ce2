"""The ego drives through its joints: Ackermann hinges, wheel torque and brake, no resets."""

from __future__ import annotations

import math

import numpy as np
import pytest

from world.core.rates import PHYSICS_RATE
from world.ego.body import ackermann, bicycle_angle
from world.spec import EgoSpec, RoadSpec, SegmentSpec, WorldSpec
from world.world import World


def _straight_world(speed: float = 0.0) -> World:
    road = RoadSpec(
        segments=(SegmentSpec(length=2000.0, curvature=0.0, lanes=2, oncoming_lanes=0,
                              lane_width=3.5, shoulder=2.5),),
        speed_limit=30.0,
    )
    spec = WorldSpec(road=road, ego=EgoSpec(lane=0, s=20.0, speed=speed, max_speed=15.0), seed=0)
    return World(spec)


@pytest.mark.parametrize("delta", [-0.5, -0.2, -0.01, 0.0, 0.01, 0.3, 0.6])
def test_ackermann_split_and_its_inverse(delta: float) -> None:
    left, right = ackermann(delta, 2.7, 1.4)
    if delta > 0:
        assert left > delta > right > 0  # the inner (left) wheel turns more
    elif delta < 0:
        assert right < delta < left < 0
    assert bicycle_angle(left, right) == pytest.approx(delta, abs=1e-12)
    if delta != 0.0:  # both wheels point at one turn centre on the rear axle line
        radius = 2.7 / math.tan(delta)
        assert 2.7 / math.tan(left) == pytest.approx(radius - 0.7)
        assert 2.7 / math.tan(right) == pytest.approx(radius + 0.7)


def test_wheel_spin_matches_speed_and_the_base_is_never_reset() -> None:
    world = _straight_world()
    ego_body = world.ego.body
    resets: list[str] = []
    for name in ("resetBasePositionAndOrientation", "resetBaseVelocity", "resetJointState"):
        real = getattr(world.client, name)

        def spy(body: int, *args: object, _name: str = name, _real: object = real,
                **kw: object) -> object:
            if body == ego_body:
                resets.append(_name)
            return _real(body, *args, **kw)  # type: ignore[operator]

        setattr(world.client, name, spy)
    try:
        spins, speeds = [], []
        for step in range(PHYSICS_RATE * 12):
            if step % 6 == 0:  # a gentle drive torque: ~1 m/s^2, no wheel slip
                world.ego.apply(0.0, 600.0 if world.ego_truth.speed < 10.0 else 120.0, 0.0)
            world.step()
            if step % 24 == 0 and step > PHYSICS_RATE * 2:
                truth = world.ego_truth
                spins.append(truth.wheel_spin.copy())
                speeds.append(truth.speed)
    finally:
        world.close()
    assert resets == []
    radius = world.ego.geometry.wheel_radius
    rim = np.array(spins) * radius  # [m/s] wheel surface speed
    v = np.array(speeds)[:, None]
    assert np.all(v > 1.0)
    assert np.all(np.abs(rim - v) <= 0.05 * v), "wheel spin differs from v / r by > 5 %"


def test_drive_brake_and_hold() -> None:
    world = _straight_world(speed=10.0)
    try:
        v0 = world.ego_truth.speed
        world.ego.apply(0.0, 0.0, 1500 * 4.0 * 0.33)  # ~4 m/s^2 of brake
        for _ in range(PHYSICS_RATE):
            world.step()
        v1 = world.ego_truth.speed
        assert 3.0 < (v0 - v1) < 5.0  # [m/s] decelerated at about 4 m/s^2
        for _ in range(PHYSICS_RATE * 4):
            world.step()
        assert abs(world.ego_truth.speed) < 0.01  # the brake holds the car at rest
        x_rest = world.ego_truth.position.copy()
        for _ in range(PHYSICS_RATE):
            world.step()
        assert np.linalg.norm(world.ego_truth.position - x_rest) < 0.005
    finally:
        world.close()


def test_steering_turns_the_car_on_the_radius_the_ackermann_geometry_gives() -> None:
    world = _straight_world(speed=5.0)
    delta = 0.2
    try:
        yaw_rates = []
        for step in range(PHYSICS_RATE * 8):
            if step % 6 == 0:
                world.ego.apply(delta, 180.0 if world.ego_truth.speed < 5.0 else 60.0, 0.0)
            world.step()
            if step > PHYSICS_RATE * 4:
                t = world.ego_truth
                yaw_rates.append(t.yaw_rate / max(t.speed, 0.1))
        curvature = float(np.mean(yaw_rates))  # [1/m] yaw rate / speed
    finally:
        world.close()
    assert world.ego_truth.steering_angle == pytest.approx(delta, abs=0.01)
    assert curvature == pytest.approx(math.tan(delta) / 2.7, rel=0.1)
