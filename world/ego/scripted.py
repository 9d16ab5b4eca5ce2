"""The car under test moved by its scenario's script, as an NPC is: a kinematic body.

`ScriptedEgo` holds the ego's state in route coordinates in an `NpcMotion` (the same
machinery as the actors': its Init speed held in its lane until a storyboard's command
changes the speed or the lateral place) and, after every physics step, puts the URDF body
where the motion is: base pose (the body centre on the route at the motion's station and
offset, heading along its course) and base velocity (the ground speed along that heading,
the yaw rate of the course). Nothing drives the joints; the truth (`EgoBody.truth`) reads the
placed pose and velocity, so criteria and conditions judge the script's car.
"""

from __future__ import annotations

import math

from pybullet_utils.bullet_client import BulletClient

from world.actors.behaviour import NpcMotion
from world.ego.body import EgoBody
from world.hdmap import RoadMap


class ScriptedEgo:
    """The ego body placed on its motion after each physics step (module doc)."""

    def __init__(self, client: BulletClient, body: EgoBody, road: RoadMap, lane: int,
                 s: float, speed: float, offset: float = 0.0) -> None:
        """`body`: the ego in `client`; `lane`: the route lane it starts in, `offset` [m]
        left of its centre; `s` [m] its centre's station, `speed` [m/s] its Init speed."""
        self._body = body
        self._road = road
        start = road.lane(lane)
        self.motion = NpcMotion(s, float(start.offset_at(s)) + offset, speed, start.direction, (),
                                lane=lane)
        self._reset_pose = client.resetBasePositionAndOrientation  # bound once: every step
        self._reset_velocity = client.resetBaseVelocity
        self._com = body.com_offset
        self._z = body.geometry.wheel_radius  # [m] the base link origin's height, as spawned
        self.place()

    def step(self, t: float, dt: float) -> None:
        """Advance the motion by dt [s] (t [s]: the time at its start) and place the body."""
        m = self.motion
        m.step(t, dt, self._road.line.curvature_one(m.s))
        self.place()

    def place(self) -> None:
        """Base pose and velocity from the motion (module doc)."""
        m = self.motion
        x, y, heading = self._road.line.pose_one(m.s, m.offset)
        yaw = heading + m.heading_offset
        c, s = math.cos(yaw), math.sin(yaw)
        com = self._com
        position = (x + c * com[0] - s * com[1], y + s * com[0] + c * com[1], self._z + com[2])
        self._reset_pose(self._body.body, position, (0.0, 0.0, math.sin(yaw / 2),
                                                    math.cos(yaw / 2)))
        v = m.ground_speed
        k = self._road.line.curvature_one(m.s)
        self._reset_velocity(self._body.body, (v * c, v * s, 0.0), (0.0, 0.0, m.speed * k))
