"""The environment in a world: the cameras render fog and darkness (seeded, and clear
daylight exactly as without it), the LiDAR loses returns in fog by the two-way extinction,
the road takes the friction scale, and a snapshot carries the environment to a mirror."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import replace

import numpy as np
import pytest
from numpy.typing import NDArray

from avsim.scenario.load import load_scenario
from world.core.client import GROUND_FRICTION
from world.core.rates import PHYSICS_RATE
from world.environment import CLEAR, SceneEnvironment, fog_extinction
from world.frames import CameraFrame, LidarScan
from world.sensors.camera import Camera, CameraSensor
from world.sensors.setup import Profile, sensor_setup
from world.spec import ActorSpec, ActorType
from world.world import World

PARKED = 20.0  # [m] a car parked this far ahead of the ego, in its lane
NOISE = 0.2  # [m] ten times the LiDAR's range noise (1-sigma): a return's range and the range
#   its detection was decided at differ by less


@pytest.fixture(scope="module")
def world() -> Iterator[World]:
    """normal_driving with a car parked ahead, the `fast` profile's camera and LiDAR, the ego
    settled on its wheels for half a second."""
    spec = load_scenario("normal_driving").world
    parked = ActorSpec(id="parked", type=ActorType.CAR, lane=0, s=spec.ego.s + PARKED,
                       offset=0.0, speed=0.0, actions=())
    w = World(replace(spec, actors=(parked,), events=()), sensor_setup(Profile.FAST))
    for _ in range(PHYSICS_RATE // 2):
        w.step()
    yield w
    w.set_environment(CLEAR)
    w.close()


def front(w: World, env: SceneEnvironment) -> NDArray[np.uint8]:
    w.set_environment(env)
    frame = w.rig.capture(["front"], w.t, w.ego_truth)[0].frame
    assert isinstance(frame, CameraFrame)
    return frame.rgb


def scan(w: World, env: SceneEnvironment) -> LidarScan:
    w.set_environment(env)
    frame = w.rig.capture(["lidar"], w.t, w.ego_truth)[0].frame
    assert isinstance(frame, LidarScan)
    return frame


def test_clear_daylight_renders_as_without_an_environment(world: World) -> None:
    before = front(world, CLEAR)
    front(world, replace(CLEAR, fog_visual_range=30.0, illuminance=2.0))
    assert front(world, CLEAR).tobytes() == before.tobytes()
    bright = replace(CLEAR, illuminance=20_000.0)  # any daylight: the auto-exposure's
    assert front(world, bright).tobytes() == before.tobytes()


def test_fog_greys_the_road_ahead_and_night_darkens_it(world: World) -> None:
    clear = front(world, CLEAR).astype(float)
    fog = front(world, replace(CLEAR, fog_visual_range=30.0)).astype(float)
    night = front(world, replace(CLEAR, illuminance=1.0)).astype(float)
    h, w = clear.shape[:2]
    road = (slice(round(0.53 * h), round(0.58 * h)), slice(round(0.3 * w), round(0.7 * w)))
    #   the road 15 to 40 m ahead, just below the horizon
    # the far road's pixels lose their spread (lines against asphalt) in fog, and at night
    assert fog[road].std() < 0.5 * clear[road].std()
    assert fog[road].mean() > clear[road].mean()  # the airlight is brighter than asphalt
    assert night.mean() < 0.2 * clear.mean()


def test_the_same_seed_gives_the_same_image(world: World) -> None:
    """A second camera of the same seed (as the render worker's) draws the same noise."""
    night = replace(CLEAR, illuminance=3.0, fog_visual_range=60.0)
    sensor = world.rig.sensor("front")
    assert isinstance(sensor, CameraSensor)
    a = front(world, night)
    b = front(world, night)
    assert world.renderer is not None
    twin = Camera(world.client, sensor.camera.info, world.renderer, (world.spec.seed, 4, 0))
    twin.environment = night
    c = CameraSensor(twin, sensor.timing, sensor.ride_height).capture(world.t, world.ego_truth)
    assert isinstance(c.frame, CameraFrame)
    assert a.tobytes() == b.tobytes() == c.frame.rgb.tobytes()
    other = Camera(world.client, sensor.camera.info, world.renderer, (world.spec.seed + 1, 4, 0))
    other.environment = night
    d = CameraSensor(other, sensor.timing, sensor.ride_height).capture(world.t, world.ego_truth)
    assert isinstance(d.frame, CameraFrame)
    assert d.frame.rgb.tobytes() != a.tobytes()


def key(s: LidarScan) -> NDArray[np.int64]:
    """Each return's ray: ring and column in one number."""
    return s.ring.astype(np.int64) * 100_000 + s.column


def lost_beyond(visual_range: float, max_range: float) -> float:
    """[m] where the margin 2 (R / d)^2 exp(-2 alpha d) falls to 1 (returns lost beyond)."""
    alpha = fog_extinction(visual_range)
    lo, hi = 0.1, max_range
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if 2.0 * (max_range / mid) ** 2 * math.exp(-2 * alpha * mid) > 1 \
            else (lo, mid)
    return lo


def test_lidar_returns_are_lost_in_fog_by_the_two_way_extinction(world: World) -> None:
    clear = scan(world, CLEAR)
    reach = np.linalg.norm(clear.points, axis=1)
    assert reach.max() > 60.0
    for v in (30.0, 100.0):
        foggy = scan(world, replace(CLEAR, fog_visual_range=v))
        r = np.linalg.norm(foggy.points, axis=1)
        limit = lost_beyond(v, clear.info.max_range)
        assert r.max() <= limit + NOISE
        sure = lost_beyond(v, clear.info.max_range / math.sqrt(2.0)) - NOISE  # margin >= 2
        kept = np.isin(key(clear)[reach < sure], key(foggy))
        assert kept.all()  # every ray's return kept where the margin holds
    # 30 m fog: the parked car's back (20 m) is lost (margin 0.27); at 100 m it is seen
    assert lost_beyond(30.0, clear.info.max_range) < PARKED - 2.5
    assert lost_beyond(100.0, clear.info.max_range) > PARKED + 2.5


def test_road_friction_scales(world: World) -> None:
    c = world.client
    world.set_environment(replace(CLEAR, friction_scale=0.3))
    assert c.getDynamicsInfo(world.scene.ground, -1)[1] == pytest.approx(0.3 * GROUND_FRICTION)
    for body in world.scene.bump_bodies:
        assert c.getDynamicsInfo(body, -1)[1] == pytest.approx(0.3 * GROUND_FRICTION)
    world.set_environment(CLEAR)
    assert c.getDynamicsInfo(world.scene.ground, -1)[1] == pytest.approx(GROUND_FRICTION)


def test_a_snapshot_carries_the_environment(world: World) -> None:
    fog = replace(CLEAR, fog_visual_range=50.0)
    world.set_environment(fog)
    snap = world.snapshot()
    world.set_environment(CLEAR)
    world.apply_snapshot(snap)
    assert world.environment == fog
    sensor = world.rig.sensor("front")
    assert isinstance(sensor, CameraSensor) and sensor.camera.environment == fog
    world.set_environment(CLEAR)
