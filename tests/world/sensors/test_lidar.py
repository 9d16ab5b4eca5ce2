"""The LiDAR: beam layout, ranges against known geometry, noise and dropout, ground truth,
the ego's own body skipped, and the ray culling equal to casting every ray."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from avsim.scenario.load import load_scenario
from world.actors.catalogue import CATALOGUE, DEFAULT_MODEL
from world.sensors.bullet_caster import BulletCaster
from world.sensors.lidar import RAY_MASK, Lidar, beam_directions
from world.sensors.sensor import vehicle_pose
from world.sensors.setup import Profile, sensor_setup
from world.spec import ActorSpec, ActorType
from world.world import World


@pytest.fixture(scope="module")
def world() -> World:
    """normal_driving with a car parked 20 m ahead in the ego's lane, LiDAR only."""
    spec = load_scenario("normal_driving").world
    parked = ActorSpec(id="parked", type=ActorType.CAR, lane=0, s=spec.ego.s + 20.0,
                       offset=0.0, speed=0.0, actions=())
    spec = replace(spec, actors=(*spec.actors, parked))
    w = World(spec, sensor_setup(Profile.DEFAULT), cameras=False)
    yield w
    w.close()


def scan(w: World):  # type: ignore[no-untyped-def]
    lidar = w.rig.sensor("lidar").lidar  # type: ignore[attr-defined]
    assert isinstance(lidar, Lidar)
    return lidar, lidar.scan(w.t, *vehicle_pose(w.ego_truth, w.ego.geometry.ride_height))


def test_beam_layout() -> None:
    info = sensor_setup(Profile.DEFAULT).lidar
    dirs, ring, column = beam_directions(info)
    assert dirs.shape == (28_800, 3) and info.rays == 28_800
    np.testing.assert_allclose(np.linalg.norm(dirs, axis=1), 1.0)
    elevation = np.degrees(np.arcsin(dirs[:, 2]))
    np.testing.assert_allclose(elevation[ring == 0], -15.0)
    np.testing.assert_allclose(elevation[ring == 15], 15.0)
    azimuth = np.degrees(np.arctan2(dirs[:, 1], dirs[:, 0])) % 360.0
    np.testing.assert_allclose(azimuth[column == 450], 90.0, atol=1e-9)  # 0.2 deg steps


def test_car_ahead_ground_and_truth(world: World) -> None:
    lidar, (s, truth) = scan(world)
    info = lidar.info
    assert len(s.points) == len(truth.actor) == len(s.ring) == len(s.column)
    # the parked car (actor index = its place in the scenario): its rear end is 20 m less
    # its half length ahead of the ego's centre, the LiDAR sits at the centre
    parked = len(world.spec.actors) - 1
    on_car = s.points[truth.actor == parked]
    assert len(on_car) > 50
    ahead = on_car[np.abs(on_car[:, 1]) < 0.3]
    half_length = 0.5 * CATALOGUE[DEFAULT_MODEL["car"]].length
    # the car is its shape: the returns of the ring that meets its rear (the nearest ones)
    # lie on its rear end; the rings above meet the sloping boot and rear window further on
    rear = ahead[ahead[:, 0] < ahead[:, 0].min() + 0.3]
    assert np.median(rear[:, 0]) == pytest.approx(20.0 - half_length, abs=0.05)
    # ground returns lie on z = 0 in the vehicle frame (sensor at 1.57 m)
    down = (truth.actor < 0) & (s.ring == 0)
    height = info.mount.to_vehicle(s.points[down].astype(np.float64))[:, 2]
    assert np.median(np.abs(height)) < 0.03
    # nothing on the ego itself: no return closer than its body's corner
    assert np.min(np.linalg.norm(s.points[:, :2], axis=1)) > 2.5


def test_a_hidden_actor_is_passed_through_by_both_backends(world: World) -> None:
    """`World.set_actor_visibility(lidar=False)`: no return on the parked car (Embree, the
    world's caster; Bullet, by the collision group the rays skip), and the rays reach
    what is behind it; shown again, it is seen again."""
    parked = len(world.spec.actors) - 1
    lidar = world.rig.sensor("lidar").lidar  # type: ignore[attr-defined]
    bullet = BulletCaster(world.client, lidar.info.max_range, lidar.info.azimuth_steps,
                          world.actors.bodies, world.scene.ground,
                          sorted(world.scene.static_bodies))
    origin, rotation = vehicle_pose(world.ego_truth, world.ego.geometry.ride_height)
    r = rotation @ lidar._mount_rot
    o, dirs = origin + rotation @ lidar._mount_xyz, lidar._dirs @ r.T
    body = world.actors.bodies[parked]

    def bullet_hits() -> int:
        hit, _ = bullet.cast(o, dirs, math.atan2(r[1, 0], r[0, 0]))
        return int((hit == body).sum())

    seen = bullet_hits()
    assert seen > 50
    world.set_actor_visibility(parked, cameras=True, lidar=False)
    bullet.hide(frozenset({body}))
    _, (_, truth) = scan(world)
    assert not (truth.actor == parked).any() and bullet_hits() == 0
    world.set_actor_visibility(parked, cameras=True, lidar=True)
    bullet.hide(frozenset())
    _, (_, truth) = scan(world)
    assert (truth.actor == parked).sum() > 50 and bullet_hits() == seen


def test_culled_cast_equals_casting_every_ray(world: World) -> None:
    """At several poses along the route, buildings, signs and the parked car in view (the
    Bullet backend, whose culling this is)."""
    lidar = world.rig.sensor("lidar").lidar  # type: ignore[attr-defined]
    caster = BulletCaster(world.client, lidar.info.max_range, lidar.info.azimuth_steps,
                          world.actors.bodies, world.scene.ground,
                          sorted(world.scene.static_bodies))
    for _ in range(4):
        for _ in range(240):
            world.ego.apply(0.0, 1500.0 * 2.0 * 0.33, 0.0)
            world.step()
        origin, rotation = vehicle_pose(world.ego_truth, world.ego.geometry.ride_height)
        r = rotation @ lidar._mount_rot
        o = origin + rotation @ lidar._mount_xyz
        dirs = lidar._dirs @ r.T
        body, fraction = caster.cast(o, dirs, math.atan2(r[1, 0], r[0, 0]))
        ends = o + dirs * lidar.info.max_range
        full = []
        for i in range(0, len(ends), 16_383):
            full += world.client.rayTestBatch(np.broadcast_to(o, ends[i:i + 16_383].shape),
                                              ends[i:i + 16_383], collisionFilterMask=RAY_MASK)
        np.testing.assert_array_equal(body, [h[0] for h in full])
        np.testing.assert_allclose(fraction, [h[2] for h in full], atol=1e-9)
        assert (body == world.scene.ground).sum() > 5000  # the ground was in closed form


def test_noise_and_dropout_are_seeded() -> None:
    spec = replace(load_scenario("normal_driving").world, actors=())
    quiet = sensor_setup(Profile.FAST)
    noisy = replace(quiet, lidar=replace(quiet.lidar, range_sigma=0.1, dropout=0.25))
    scans = []
    for setup in (quiet, noisy, noisy):
        w = World(spec, setup, cameras=False)
        scans.append(scan(w)[1][0])
        w.close()
    exact, a, b = scans
    np.testing.assert_array_equal(a.points, b.points)  # same seed, same noise
    assert len(a.points) == pytest.approx(0.75 * len(exact.points), rel=0.03)
    key = exact.ring.astype(int) * 10_000 + exact.column
    common = np.isin(key, a.ring.astype(int) * 10_000 + a.column)
    r0 = np.linalg.norm(exact.points[common], axis=1)
    r1 = np.linalg.norm(a.points, axis=1)
    assert np.std(r1 - r0) == pytest.approx(0.1, rel=0.1)
