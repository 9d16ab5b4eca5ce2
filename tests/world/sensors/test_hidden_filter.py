"""An actor hidden from the LiDAR's rays (`BulletCaster.hide`) and shown again gets
PyBullet's own collision filter back: the contact pairs of a static box (an actor: mass 0)
with a dynamic box and with another static box are the same before hiding and after
showing; while hidden it still meets the dynamic box."""

from __future__ import annotations

import pybullet
from pybullet_utils.bullet_client import BulletClient

from world.sensors.bullet_caster import BulletCaster


def _box(c: BulletClient, mass: float, x: float) -> int:
    """A 2 m cube at x [m], made as the actors' bodies are (maximal coordinates)."""
    shape = c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=[1.0, 1.0, 1.0])
    return int(c.createMultiBody(baseMass=mass, baseCollisionShapeIndex=shape,
                                 basePosition=[x, 0.0, 1.0], useMaximalCoordinates=True))


def _pairs(c: BulletClient, bodies: list[int]) -> set[tuple[int, int]]:
    c.performCollisionDetection()
    return {(a, b) for a in bodies for b in bodies
            if a < b and c.getContactPoints(bodyA=a, bodyB=b)}


def test_an_actor_shown_again_collides_as_before() -> None:
    c = BulletClient(connection_mode=pybullet.DIRECT)
    try:
        actor, car, other = _box(c, 0.0, 0.0), _box(c, 1.0, 1.5), _box(c, 0.0, -1.5)
        bodies = [actor, car, other]
        before = _pairs(c, bodies)
        assert before == {(actor, car)}  # overlapping static boxes (actor, other) never touch
        caster = BulletCaster(c, 100.0, 8, [actor], -1, [])
        caster.hide(frozenset({actor}))
        assert (actor, car) in _pairs(c, bodies)  # hidden from the rays only: still hit
        caster.hide(frozenset())
        assert _pairs(c, bodies) == before  # PyBullet's own filter back
    finally:
        c.disconnect()
