"""Actors' bodies built from their shapes, as the physics and the LiDAR casters see them.

A saloon (the catalogue's `sedan`) posed 10 m ahead, facing the sensor: rays that would hit
its box pass over its bonnet and meet the windscreen; a ray from above meets the roof; the
Embree caster (exact: float32 and the tessellation of its tyres) and Bullet's agree on
which rays hit it, and on the range within `BULLET_SHAPE_SLACK` (Bullet's 1 mm margin
around hulls, seen at a glancing incidence, and its convex cast on a tyre's flat side:
`test_embree_lidar`'s module docstring); most hits agree within 2 mm. Bullet's ray test lets
rays through the lower half of a tyre's tread to the ground under the car (measured: 66 of
4,219 hits, 2 to 30 cm above the ground, found by Embree where the closed-form circle has
them), so the casters are compared above the tyres.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from tests.world.sensors.ray_fans import ray_fan
from world.actors.body_build import BodyBuilder
from world.actors.shapes.actors import vehicle_shape
from world.core.client import add_ground, make_client
from world.frames import import_open3d
from world.scene.collision import CollisionShapes, Part
from world.sensors.bullet_caster import BulletCaster
from world.sensors.embree_caster import EmbreeCaster
from world.sensors.tessellate import body_triangles

BULLET_SHAPE_SLACK = 0.030  # [m] (module docstring)
CENTRE = (10.0, 0.0, 0.73)  # [m] the saloon's box centre: 1.46 m high, on the ground
REACH = 100.0  # [m]
TYRES_TOP = 0.7  # [m] above the tyres (0.668 m high)


def _saloon() -> tuple[BulletClient, CollisionShapes, int, int]:
    client = make_client()
    ground = add_ground(client)
    shapes = CollisionShapes()
    shape = vehicle_shape("sedan", 4.77, 1.83)
    assert shape is not None
    body = BodyBuilder(client, shapes).shaped(shape, 1.46, (0.8, 0.2, 0.1, 1.0))
    facing = client.getQuaternionFromEuler([0.0, 0.0, math.pi])  # its front to the origin
    client.resetBasePositionAndOrientation(body, CENTRE, facing)
    return client, shapes, ground, body


def _distance(parts: tuple[Part, ...], client: BulletClient, body: int,
              points: NDArray[np.float64]) -> NDArray[np.float64]:
    """[m] each point's distance to the surface of `parts` of `body` where it is."""
    o3d = import_open3d()
    position, quaternion = client.getBasePositionAndOrientation(body)
    rotation = np.array(client.getMatrixFromQuaternion(quaternion)).reshape(3, 3)
    vertices, triangles = body_triangles(parts, np.array(position), rotation)
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(vertices.astype(np.float32)),
                        o3d.core.Tensor(triangles.astype(np.uint32)))
    d = scene.compute_distance(o3d.core.Tensor(points.astype(np.float32)))
    return np.asarray(d.numpy(), dtype=np.float64)


def _named(shapes: CollisionShapes, body: int, names: tuple[str, ...]) -> tuple[Part, ...]:
    shape = vehicle_shape("sedan", 4.77, 1.83)
    assert shape is not None
    keep = [i for i, p in enumerate(shape.parts) if p.name in names]
    return tuple(shapes.parts(body)[i] for i in keep)


def test_rays_pass_over_a_saloons_bonnet_and_meet_its_glass_and_roof() -> None:
    client, shapes, ground, body = _saloon()
    caster = EmbreeCaster(client, shapes, REACH, [body], ground, [])
    front = CENTRE[0] - 4.77 / 2  # [m] where its box's front face is
    # level rays 1.1 m above the ground, across the middle of the car: over the bonnet
    # (0.96 m at most), under the box's top (1.46 m)
    origin = np.array([0.0, 0.0, 1.1])
    angles = np.linspace(-0.02, 0.02, 21)
    dirs = np.column_stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)])
    hit, fraction = caster.cast(origin, dirs, 0.0)
    assert np.all(hit == body)
    ranges = fraction * REACH
    assert np.all(ranges > front + 0.8)  # well past where the box would have been met
    points = origin + dirs * ranges[:, None]
    glass = _named(shapes, body, ("glass",))
    assert np.max(_distance(glass, client, body, points)) <= 1e-3
    # from above, over the cabin: the roof at 1.46 m
    down = np.array([[0.0, 0.0, -1.0]])
    hit, fraction = caster.cast(np.array([CENTRE[0] + 0.4, 0.0, 5.0]), down, 0.0)
    assert hit[0] == body
    assert abs(5.0 - fraction[0] * REACH - 1.46) <= 1e-4


def test_embree_and_bullet_agree_on_a_shaped_actor() -> None:
    client, shapes, ground, body = _saloon()
    embree = EmbreeCaster(client, shapes, REACH, [body], ground, [])
    columns = 7200
    bullet = BulletCaster(client, REACH, columns, [body], ground, [])
    origin = np.array([0.0, 0.4, 1.2])
    dirs = ray_fan(-9.0, 3.0, 24, columns)
    b_e, f_e = embree.cast(origin, dirs, 0.0)
    b_b, f_b = bullet.cast(origin, dirs, 0.0)
    on_e, on_b = b_e == body, b_b == body
    assert on_e.sum() > 1000
    # above the tyres (0.67 m high), where Bullet's ray test lets rays through (module doc)
    z_e = origin[2] + dirs[:, 2] * f_e * REACH
    z_b = origin[2] + dirs[:, 2] * f_b * REACH
    above = np.minimum(np.where(on_e, z_e, np.inf), np.where(on_b, z_b, np.inf)) > TYRES_TOP
    on_e, on_b = on_e & above, on_b & above
    assert np.sum(on_e != on_b) <= 0.01 * on_e.sum()  # rays grazing an edge
    both = on_e & on_b
    error = np.abs(f_e - f_b)[both] * REACH
    print(f"\n{on_e.sum()} hits, {np.sum(on_e != on_b)} disagree; range error median "
          f"{np.median(error) * 1e3:.2f} mm, 95 % {np.quantile(error, 0.95) * 1e3:.2f} mm, "
          f"worst {error.max() * 1e3:.2f} mm")
    assert np.median(error) <= 2e-3
    assert error.max() <= BULLET_SHAPE_SLACK
    points = origin + dirs[on_e] * (f_e[on_e, None] * REACH)
    assert np.max(_distance(shapes.parts(body), client, body, points)) <= 1e-3
