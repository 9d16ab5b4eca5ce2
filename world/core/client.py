"""One PyBullet client per world (DIRECT, headless) and the fixed-step clock.

Everything static or kinematic (ground, road meshes, buildings, signs, NPC boxes) is made with
``useMaximalCoordinates=True``: a plain static rigid body costs nothing per step, while a
mass-0 multibody still goes through the articulated-body pass every step. Only the ego is a
multibody (its joints).

Two worlds can live in one process: nothing here touches the module-global pybullet
connection; every call goes through the `BulletClient` passed around explicitly.
"""

from __future__ import annotations

import pybullet
from pybullet_utils.bullet_client import BulletClient

from world.core.quiet import quiet_c_output
from world.core.rates import PHYSICS_RATE

GRAVITY = 9.81  # [m/s^2]
GROUND_EXTENT = 2000.0  # [m] half size of the visible ground
GROUND_FRICTION = 1.0  # [-] dry asphalt; Bullet multiplies it with the tyre's (URDF) friction


def make_client() -> BulletClient:
    """A new headless physics server with gravity and the fixed 240 Hz step."""
    with quiet_c_output():  # the connection prints its (empty) argv
        client = BulletClient(connection_mode=pybullet.DIRECT)
    client.setGravity(0.0, 0.0, -GRAVITY)
    client.setTimeStep(1.0 / PHYSICS_RATE)
    # Pyramid friction, not the cone: Bullet picks the first friction direction along the
    # contact's slip velocity, so a sliding tyre still gets |F| <= mu N along its slip; only
    # combined (braking while cornering) grip near the limit can reach sqrt(2) mu N. The cone
    # doubles the cost of a step once the car's axes leave the world's, for the same speeds.
    client.setPhysicsEngineParameter(deterministicOverlappingPairs=1, enableConeFriction=0)
    return client


def add_ground(client: BulletClient) -> int:
    """An infinite flat ground plane at z = 0 (the road meshes are painted on top of it)."""
    shape = client.createCollisionShape(pybullet.GEOM_PLANE)
    visual = client.createVisualShape(  # grass, a thin 4 km square just below z = 0
        pybullet.GEOM_BOX, halfExtents=[GROUND_EXTENT, GROUND_EXTENT, 0.01],
        visualFramePosition=[0.0, 0.0, -0.011], rgbaColor=[0.33, 0.45, 0.25, 1.0],
    )
    body = client.createMultiBody(0.0, shape, visual, useMaximalCoordinates=True)
    client.changeDynamics(body, -1, lateralFriction=GROUND_FRICTION)
    return int(body)


class Clock:
    """Counts physics steps; time is derived from the step count (no float drift)."""

    def __init__(self) -> None:
        self.step = 0

    @property
    def t(self) -> float:
        """[s] simulated time."""
        return self.step / PHYSICS_RATE

    @property
    def dt(self) -> float:
        """[s] the physics step."""
        return 1.0 / PHYSICS_RATE

    def advance(self) -> None:
        self.step += 1
