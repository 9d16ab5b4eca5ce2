"""The `truth` observation: privileged ground truth no real car's stack has (for learning
and baselines; the `info` dict says `privileged: True`).

- `ego` float32 (7,): x, y [m] map frame, car centre; yaw [rad] counter-clockwise from +x;
  forward speed [m/s]; yaw rate [rad/s]; station along the route [m]; offset from the
  centre of the lane it is in [m] (left +, 0 off the lanes);
- `actors` float32 (K, 7): the K nearest road users and obstacles by centre distance,
  nearest first, each in the car's frame (x forward, y left, at its centre): dx, dy [m],
  relative yaw [rad], velocity relative to the car's vx, vy [m/s] (an actor's velocity is
  its speed along its heading), length, width [m]; rows past the actors there are zero;
- `actors_mask` int8 (K,): 1 for a real row.
"""

from __future__ import annotations

import math

import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from world.frames import wrap_angle
from world.world import World

Observation = dict[str, NDArray[np.generic]]
EGO_SIZE = 7
ACTOR_SIZE = 7


class TruthObservation:
    """The space and the arrays of the `truth` observation with `nearest` actor rows."""

    def __init__(self, nearest: int) -> None:
        self.nearest = nearest
        self.space = spaces.Dict({
            "ego": spaces.Box(-np.inf, np.inf, (EGO_SIZE,), np.float32),
            "actors": spaces.Box(-np.inf, np.inf, (nearest, ACTOR_SIZE), np.float32),
            "actors_mask": spaces.MultiBinary(nearest),
        })

    def encode(self, world: World, lane_error: float) -> Observation:
        """The truth now; `lane_error` [m] the car's offset from its lane's centre."""
        truth, route = world.ego_truth, world.ego_route
        x, y = float(truth.position[0]), float(truth.position[1])
        ego = np.array([x, y, truth.yaw, truth.speed, truth.yaw_rate, route.station,
                        lane_error if math.isfinite(lane_error) else 0.0], np.float32)
        actors = np.zeros((self.nearest, ACTOR_SIZE), np.float32)
        mask = np.zeros(self.nearest, np.int8)
        if world.actors.bodies:
            p = world.actors.poses
            c, s = math.cos(truth.yaw), math.sin(truth.yaw)
            d = p.centres[:, :2] - np.array([x, y])
            order = np.argsort(np.hypot(d[:, 0], d[:, 1]), kind="stable")[:self.nearest]
            v = np.column_stack([p.speeds * np.cos(p.yaws), p.speeds * np.sin(p.yaws)]) \
                - truth.velocity[:2]
            for row, i in enumerate(order.tolist()):
                actors[row] = (c * d[i, 0] + s * d[i, 1], -s * d[i, 0] + c * d[i, 1],
                               wrap_angle(float(p.yaws[i]) - truth.yaw),
                               c * v[i, 0] + s * v[i, 1], -s * v[i, 0] + c * v[i, 1],
                               2 * p.half_sizes[i, 0], 2 * p.half_sizes[i, 1])
                mask[row] = 1
        return {"ego": ego, "actors": actors, "actors_mask": mask}
