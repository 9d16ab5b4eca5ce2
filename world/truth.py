"""Ground-truth queries: for criteria, perception scoring and the recording, never the stack.

Points are in the map frame [m]; the car's points are its base link origin (the centre) and
points offset from it along the body's forward and left axes in the map plane (the body's
yaw only), by the URDF's geometry: front axle `front_axle` ahead, rear axle `rear_axle`
behind, tyres `track / 2` each side.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from vehicle_urdf import CarGeometry
from world.ego.body import EgoTruth
from world.hdmap import ReferenceLine


def body_axes(truth: EgoTruth) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit forward and left vectors (2,) of the car in the map plane, from its yaw."""
    c, s = np.cos(truth.yaw), np.sin(truth.yaw)
    return np.array([c, s]), np.array([-s, c])


def tyre_patches(truth: EgoTruth, g: CarGeometry) -> NDArray[np.float64]:
    """[m] (4, 2) map-frame centres of the tyre contact patches, FL, FR, RL, RR."""
    fwd, left = body_axes(truth)
    x = np.array([g.front_axle, g.front_axle, -g.rear_axle, -g.rear_axle])
    y = np.array([g.track / 2, -g.track / 2, g.track / 2, -g.track / 2])
    return truth.position[:2] + x[:, None] * fwd + y[:, None] * left


def front_axle_point(truth: EgoTruth, g: CarGeometry) -> NDArray[np.float64]:
    """[m] (2,) map-frame centre of the front axle."""
    fwd, _ = body_axes(truth)
    return np.asarray(truth.position[:2] + g.front_axle * fwd)


@dataclass(frozen=True, slots=True, eq=False)
class RouteTruth:
    """The ego's true points on the route: centre, front axle and the four tyre patches,
    with their stations and offsets from the reference line (left +), from one projection."""

    points: NDArray[np.float64]  # [m] (6, 2) map frame: centre, front axle, FL, FR, RL, RR
    stations: NDArray[np.float64]  # [m] (6,) on the route
    offsets: NDArray[np.float64]  # [m] (6,) from the reference line, left +

    @property
    def station(self) -> float:
        """[m] the car centre's station."""
        return float(self.stations[0])

    @property
    def tyres(self) -> NDArray[np.float64]:
        """[m] (4, 2) the tyre patches, FL, FR, RL, RR."""
        return self.points[2:]

    @property
    def tyre_stations(self) -> NDArray[np.float64]:
        """[m] (4,) the tyre patches' stations."""
        return self.stations[2:]

    @property
    def tyre_offsets(self) -> NDArray[np.float64]:
        """[m] (4,) the tyre patches' offsets from the reference line, left +."""
        return self.offsets[2:]


def route_truth(truth: EgoTruth, g: CarGeometry, line: ReferenceLine) -> RouteTruth:
    """Project the ego's centre, front axle and tyre patches onto the route in one call."""
    fwd, left = body_axes(truth)
    x = np.array([0.0, g.front_axle, g.front_axle, g.front_axle, -g.rear_axle, -g.rear_axle])
    y = np.array([0.0, 0.0, g.track / 2, -g.track / 2, g.track / 2, -g.track / 2])
    points = truth.position[:2] + x[:, None] * fwd + y[:, None] * left
    s, d = line.project(points)
    return RouteTruth(points, s, d)


def touching(client: BulletClient, body: int, ignore: int) -> set[int]:
    """Bodies in contact with `body` now, other than `ignore` (the ground)."""
    return {int(c[2]) for c in client.getContactPoints(bodyA=body) if c[2] != ignore}
