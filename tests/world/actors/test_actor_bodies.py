"""Actors' bodies in Bullet: the shape an actor gets, the parts kept for the casters are what
Bullet has, and what counts as contact is the shape (`no_collision` judges Bullet's
contacts: `world.truth.touching`)."""

from __future__ import annotations

import math

import numpy as np
import pybullet

from world.actors.actor_set import actor_shape, actor_walker
from world.actors.bodies import body_size
from world.actors.body_build import BodyBuilder
from world.actors.catalogue import CATALOGUE
from world.actors.shapes.actors import vehicle_shape
from world.core.client import add_ground, make_client
from world.scene.collision import CollisionShapes
from world.sensors.tessellate import body_triangles
from world.spec import ActorSpec, ActorType
from world.truth import touching


def _spec(kind: ActorType, **kw: object) -> ActorSpec:
    return ActorSpec(id="a", type=kind, lane=0, s=10.0, offset=0.0, speed=0.0,
                     **kw)  # type: ignore[arg-type]


def test_which_actors_have_a_shape() -> None:
    car = _spec(ActorType.CAR)
    assert actor_shape(car, body_size(car)) is not None  # the default model's
    truck = _spec(ActorType.TRUCK, model=CATALOGUE["bus"])
    shape = actor_shape(truck, body_size(truck))
    assert shape is not None and shape.name == "bus"
    adult = _spec(ActorType.PEDESTRIAN, size=(0.6, 0.5, 1.8))  # Euro NCAP's EPTa box
    assert actor_shape(adult, body_size(adult)) is None  # a walker, not a rigid shape
    walker = actor_walker(adult, body_size(adult))
    assert walker is not None and (walker.height, walker.width, walker.amplitude) == (1.8, 0.5,
                                                                                        1.0)
    generic = _spec(ActorType.PEDESTRIAN)  # 0.5 x 0.6 x 1.75: its full walk sweeps 0.57 m
    walker = actor_walker(generic, body_size(generic))
    assert walker is not None and walker.height == 1.75  # the box's height, a shorter stride
    assert 0.0 < walker.amplitude < 1.0
    obstacle = _spec(ActorType.OBSTACLE)
    size = body_size(obstacle)
    assert actor_shape(obstacle, size) is None and actor_walker(obstacle, size) is None
    assert vehicle_shape("NCAP_GlobalVehicleTarget", 4.023, 1.712) is not None
    assert vehicle_shape("sedan", 4.0, 1.83) is None  # not the shape's footprint


def test_the_parts_kept_are_what_bullet_has() -> None:
    """Every catalogue vehicle's body: Bullet's bounding box is its parts' (Bullet adds its
    1 mm margin around hulls and its contact threshold: within 5 mm)."""
    client = make_client()
    shapes = CollisionShapes()
    builder = BodyBuilder(client, shapes)
    for model in CATALOGUE.values():
        shape = vehicle_shape(model.name, model.length, model.width)
        assert shape is not None
        body = builder.shaped(shape, model.height, (1.0, 0.0, 0.0, 1.0))
        position = np.array([20.0, 5.0, 0.5 * model.height])
        yaw = 0.0  # a turned compound has the bounds of its turned local box
        client.resetBasePositionAndOrientation(
            body, position.tolist(), client.getQuaternionFromEuler([0.0, 0.0, yaw]))
        c, s = math.cos(yaw), math.sin(yaw)
        rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        vertices, _ = body_triangles(shapes.parts(body), position, rotation)
        lo, hi = client.getAABB(body)
        np.testing.assert_allclose(lo, vertices.min(axis=0), atol=5e-3)
        np.testing.assert_allclose(hi, vertices.max(axis=0), atol=5e-3)
        assert abs(vertices[:, 2].min()) < 1e-3  # its wheels on the ground


def test_contact_is_the_shape_not_its_box() -> None:
    """A 10 cm cube inside a saloon's box above its bonnet touches nothing; on the bonnet
    and in its box with a box body, it touches."""
    client = make_client()
    ground = add_ground(client)
    shapes = CollisionShapes()
    builder = BodyBuilder(client, shapes)
    shape = vehicle_shape("sedan", 4.77, 1.83)
    assert shape is not None
    saloon = builder.shaped(shape, 1.46, (1.0, 0.0, 0.0, 1.0))
    client.resetBasePositionAndOrientation(saloon, [0.0, 0.0, 0.73], [0.0, 0.0, 0.0, 1.0])
    bonnet = 3.0 - 3.0 * client.rayTest([2.0, 0.0, 3.0], [2.0, 0.0, 0.0])[0][2]  # [m]
    assert bonnet < 1.0
    probe_shape = client.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[0.05] * 3)
    probe = client.createMultiBody(1.0, probe_shape, -1, [2.0, 0.0, 1.3])
    client.performCollisionDetection()
    assert touching(client, probe, ground) == set()  # over the bonnet: in the box only
    client.resetBasePositionAndOrientation(probe, [2.0, 0.0, bonnet + 0.04],
                                           [0.0, 0.0, 0.0, 1.0])
    client.performCollisionDetection()
    assert touching(client, probe, ground) == {saloon}  # on the bonnet
    box = builder.box((2.385, 0.915, 0.73), (1.0, 0.0, 0.0, 1.0))
    client.resetBasePositionAndOrientation(box, [0.0, 10.0, 0.73], [0.0, 0.0, 0.0, 1.0])
    client.resetBasePositionAndOrientation(probe, [2.0, 10.0, 1.3], [0.0, 0.0, 0.0, 1.0])
    client.performCollisionDetection()
    assert touching(client, probe, ground) == {box}  # the same place in a box body
