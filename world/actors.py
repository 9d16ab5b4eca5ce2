"""NPC bodies in the physics world, moved along the route by their scripted behaviour.

NPCs are kinematic: static (mass 0) boxes placed every physics step from their
`NpcMotion` in route coordinates. The ego collides with them like with a wall, and contact
queries see them. (Only the ego must drive through its joints; NPCs are scripted traffic.)
All NPC poses come from one vectorised map call per step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pybullet
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from world.behaviour import NpcMotion, TriggerContext
from world.hdmap import RoadMap
from world.spec import ActorSpec, ActorType


@dataclass(frozen=True, slots=True)
class BoxSize:
    length: float  # [m]
    width: float  # [m]
    height: float  # [m]


SIZES = {
    ActorType.CAR: BoxSize(4.6, 1.8, 1.5),
    ActorType.TRUCK: BoxSize(9.0, 2.5, 3.4),
    ActorType.OBSTACLE: BoxSize(1.0, 1.0, 1.0),  # a crate / barrier block
    ActorType.PEDESTRIAN: BoxSize(0.5, 0.6, 1.75),
}
COLOURS = {
    ActorType.CAR: (0.85, 0.20, 0.15, 1.0),
    ActorType.TRUCK: (0.90, 0.65, 0.10, 1.0),
    ActorType.OBSTACLE: (0.95, 0.45, 0.05, 1.0),
    ActorType.PEDESTRIAN: (0.20, 0.70, 0.30, 1.0),
}


@dataclass(frozen=True, slots=True, eq=False)
class ActorPoses:
    """Ground truth of all NPCs at one instant (for criteria and the recording)."""

    ids: tuple[str, ...]
    kinds: tuple[ActorType, ...]
    centres: NDArray[np.float64]  # [m] (N, 3) map frame
    yaws: NDArray[np.float64]  # [rad] (N,)
    half_sizes: NDArray[np.float64]  # [m] (N, 3) length, width, height halves
    stations: NDArray[np.float64]  # [m] (N,) route station of each centre
    offsets: NDArray[np.float64]  # [m] (N,) lateral offset from the reference line
    speeds: NDArray[np.float64]  # [m/s] (N,) along each one's travel direction
    accels: NDArray[np.float64]  # [m/s^2] (N,) longitudinal, signed


class ActorSet:
    """All scripted actors of a world."""

    def __init__(self, client: BulletClient, road: RoadMap, specs: tuple[ActorSpec, ...]) -> None:
        self._c = client
        self._road = road
        self.specs = specs
        self.motions: list[NpcMotion] = []
        self.bodies: list[int] = []
        for spec in specs:
            lane = road.lane(spec.lane)
            offset = float(lane.offset_at(spec.s)) + spec.offset
            self.motions.append(
                NpcMotion(spec.s, offset, spec.speed, lane.direction, spec.actions)
            )
            self.bodies.append(self._make_body(spec.type))
        self.lengths = np.array([SIZES[a.type].length for a in specs])
        self.half_sizes = np.array(
            [[SIZES[a.type].length / 2, SIZES[a.type].width / 2, SIZES[a.type].height / 2]
             for a in specs]
        ).reshape(-1, 3)
        self._last_speed = np.array([a.speed for a in specs])
        self.accels = np.zeros(len(specs))  # [m/s^2]
        self._ids = tuple(a.id for a in specs)
        self._kinds = tuple(a.type for a in specs)
        self._flip = np.array([math.pi if m.direction < 0 else 0.0 for m in self.motions])
        self.poses = self._compute_poses()
        self._place(force=True)

    def _make_body(self, kind: ActorType) -> int:
        size = SIZES[kind]
        half = [size.length / 2, size.width / 2, size.height / 2]
        shape = self._c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half)
        visual = self._c.createVisualShape(
            pybullet.GEOM_BOX, halfExtents=half, rgbaColor=list(COLOURS[kind])
        )
        return int(self._c.createMultiBody(0.0, shape, visual, [0.0, 0.0, -10.0]))

    def lane_offset(self, lane: int, s: float) -> float:
        return float(self._road.lane(lane).offset_at(s))

    def gaps(self, ego_s: float, ego_length: float) -> NDArray[np.float64]:
        """[m] (N,) bumper-to-bumper distance of each actor to the ego along the route."""
        s = np.array([m.s for m in self.motions])
        return np.maximum(0.0, np.abs(s - ego_s) - (self.lengths + ego_length) / 2)

    def fire_triggers(self, t: float, ego_s: float, ego_length: float) -> list[tuple[str, int]]:
        """Start the actions whose triggers hold; returns (actor id, action index) started."""
        started = []
        for spec, motion, gap in zip(
            self.specs, self.motions, self.gaps(ego_s, ego_length), strict=True
        ):
            ctx = TriggerContext(t=t, ego_s=ego_s, gap=float(gap))
            started += [(spec.id, i) for i in motion.fire_due(ctx, self.lane_offset)]
        return started

    def step(self, t: float, dt: float, place: bool = True) -> None:
        """Advance every motion by dt [s]; with `place`, move the bodies to the new poses."""
        if not self.motions:
            return
        s = np.array([m.s for m in self.motions])
        curvature = self._road.curvature_at(s)
        for motion, k in zip(self.motions, curvature, strict=True):
            motion.step(t, dt, float(k))
        speeds = np.array([m.speed for m in self.motions])
        self.accels = (speeds - self._last_speed) / dt
        self._last_speed = speeds
        if place:
            self.poses = self._compute_poses()
            self._place(force=False)

    def _compute_poses(self) -> ActorPoses:
        m = self.motions
        s = np.array([x.s for x in m])
        offsets = np.array([x.offset for x in m])
        line = self._road.line  # the reference line: offsets are from it
        xy = line.point(s, offsets).reshape(-1, 2)
        yaws = line.heading(s) + self._flip + np.array([x.heading_offset for x in m])
        centres = np.column_stack([xy, self.half_sizes[:, 2]]) if m else np.zeros((0, 3))
        return ActorPoses(
            ids=self._ids,
            kinds=self._kinds,
            centres=centres,
            yaws=yaws,
            half_sizes=self.half_sizes,
            stations=s,
            offsets=offsets,
            speeds=np.array([x.speed for x in m]),
            accels=self.accels,
        )

    def _place(self, force: bool) -> None:
        p = self.poses
        half = p.yaws / 2
        for i, body in enumerate(self.bodies):
            moving = self.motions[i].speed != 0.0 or self.motions[i].lateral_speed != 0.0
            if force or moving:
                quat = (0.0, 0.0, math.sin(half[i]), math.cos(half[i]))
                self._c.resetBasePositionAndOrientation(body, p.centres[i].tolist(), quat)
