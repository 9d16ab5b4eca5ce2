"""Ground-truth queries: for criteria, perception scoring and the recording, never the stack."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from vehicle_urdf import CarGeometry
from world.ego import EgoTruth


def body_axes(truth: EgoTruth) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit forward and left vectors (2,) of the car in the map plane."""
    c, s = np.cos(truth.yaw), np.sin(truth.yaw)
    return np.array([c, s]), np.array([-s, c])


def tyre_patches(truth: EgoTruth, g: CarGeometry) -> NDArray[np.float64]:
    """[m] (4, 2) map-frame centres of the tyre contact patches, FL, FR, RL, RR."""
    fwd, left = body_axes(truth)
    x = np.array([g.front_axle, g.front_axle, -g.rear_axle, -g.rear_axle])
    y = np.array([g.track / 2, -g.track / 2, g.track / 2, -g.track / 2])
    return truth.position[:2] + x[:, None] * fwd + y[:, None] * left


def front_axle_point(truth: EgoTruth, g: CarGeometry) -> NDArray[np.float64]:
    fwd, _ = body_axes(truth)
    return np.asarray(truth.position[:2] + g.front_axle * fwd)


def touching(client: BulletClient, body: int, ignore: int) -> set[int]:
    """Bodies in contact with `body` now, other than `ignore` (the ground)."""
    return {int(c[2]) for c in client.getContactPoints(bodyA=body) if c[2] != ignore}
