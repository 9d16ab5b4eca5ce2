"""The `truth` observation: privileged ground truth no real car's stack has (for learning
and baselines; the `info` dict says `privileged: True`).

- `ego` float32 (7,): x, y [m] map frame, car centre; yaw [rad] counter-clockwise from +x;
  forward speed [m/s]; yaw rate [rad/s]; station along the route [m]; offset from the
  centre of the lane it is in [m] (left +, 0 off the lanes);
- `actors` float32 (K, 7): the K nearest road users and obstacles by centre distance,
  nearest first, each in the car's frame (x forward, y left, at its centre): dx, dy [m],
  relative yaw [rad], velocity relative to the car's vx, vy [m/s] (over ground, as the
  privileged truth frame gives it: `world.sensors.truth.truth_objects`), length, width [m];
  rows past the actors there are zero; an actor no sensor can see (hidden, gone) is left
  out, as from the truth frame;
- `actors_mask` int8 (K,): 1 for a real row.
"""

from __future__ import annotations

import math

import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from world.frames import wrap_angle
from world.sensors.truth import Place, truth_objects
from world.world import World

Observation = dict[str, NDArray[np.generic]]
EGO_SIZE = 7
ACTOR_SIZE = 7


class TruthObservation:
    """The space and the arrays of the `truth` observation with `nearest` actor rows."""

    def __init__(self, nearest: int, period: float) -> None:
        """`period` [s]: the time between two observations (an actor's velocity is its
        motion over it)."""
        self.nearest, self.period = nearest, period
        self._before: dict[str, Place] = {}  # the last observation's actor centres
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
        objects = truth_objects(world.actors.poses, world.unsensed, world.t, self._before,
                                self.period) if world.actors.bodies else ()
        if objects:
            c, s = math.cos(truth.yaw), math.sin(truth.yaw)
            d = np.array([(o.x - x, o.y - y) for o in objects])
            v = np.array([(o.vx, o.vy) for o in objects]) - truth.velocity[:2]
            order = np.argsort(np.hypot(d[:, 0], d[:, 1]), kind="stable")[:self.nearest]
            for row, i in enumerate(order.tolist()):
                o = objects[i]
                actors[row] = (c * d[i, 0] + s * d[i, 1], -s * d[i, 0] + c * d[i, 1],
                               wrap_angle(o.yaw - truth.yaw),
                               c * v[i, 0] + s * v[i, 1], -s * v[i, 0] + c * v[i, 1],
                               o.length, o.width)
                mask[row] = 1
        return {"ego": ego, "actors": actors, "actors_mask": mask}
