"""One PyBullet client per world (DIRECT, headless) and the fixed-step clock.

Two worlds can live in one process: nothing here touches the module-global pybullet
connection; every call goes through the `BulletClient` passed around explicitly.
"""

from __future__ import annotations

from dataclasses import dataclass

import pybullet
from pybullet_utils.bullet_client import BulletClient

PHYSICS_RATE = 240  # [Hz] fixed physics step
GRAVITY = 9.81  # [m/s^2]
GROUND_EXTENT = 2000.0  # [m] half size of the visible ground
GROUND_FRICTION = 1.0  # [-] dry asphalt; Bullet multiplies it with the tyre's (URDF) friction


def make_client() -> BulletClient:
    """A new headless physics server with gravity and the fixed 240 Hz step."""
    client = BulletClient(connection_mode=pybullet.DIRECT)
    client.setGravity(0.0, 0.0, -GRAVITY)
    client.setTimeStep(1.0 / PHYSICS_RATE)
    client.setPhysicsEngineParameter(deterministicOverlappingPairs=1)
    return client


def add_ground(client: BulletClient) -> int:
    """An infinite flat ground plane at z = 0 (the road meshes are painted on top of it)."""
    shape = client.createCollisionShape(pybullet.GEOM_PLANE)
    visual = client.createVisualShape(  # grass, a thin 4 km square just below z = 0
        pybullet.GEOM_BOX, halfExtents=[GROUND_EXTENT, GROUND_EXTENT, 0.01],
        visualFramePosition=[0.0, 0.0, -0.011], rgbaColor=[0.33, 0.45, 0.25, 1.0],
    )
    body = client.createMultiBody(0.0, shape, visual)
    client.changeDynamics(body, -1, lateralFriction=GROUND_FRICTION)
    return int(body)


@dataclass(frozen=True, slots=True)
class Rate:
    """A rate that divides the physics rate: it fires every `PHYSICS_RATE / hz` steps."""

    name: str
    hz: int  # [Hz]

    def __post_init__(self) -> None:
        if self.hz <= 0 or PHYSICS_RATE % self.hz:
            raise ValueError(f"rate {self.name} = {self.hz} Hz must divide {PHYSICS_RATE} Hz")

    @property
    def every(self) -> int:
        """[steps] between firings."""
        return PHYSICS_RATE // self.hz

    def fires(self, step: int) -> bool:
        return step % self.every == 0


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
