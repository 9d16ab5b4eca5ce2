"""NPC bodies in the physics world, moved along the route by their scripted behaviour.

NPCs are kinematic: static (mass 0) bodies, placed at `ACTOR_RATE`
(`world.core.rates`) from their `NpcMotion` in route coordinates. The ego collides with them
like with a wall, and contact queries see them. (Only the ego must drive through its joints;
NPCs are scripted traffic.) A vehicle's box is its catalogue model's (`world.actors.catalogue`:
the actor's `model`, else its type's default); a pedestrian's and an obstacle's are
`world.actors.bodies.SIZES`. The body is the actor's shape where it has one
(`world.actors.shapes.actors`: the catalogue's vehicles, the Euro NCAP targets), built from its
convex parts (`world.actors.body_build`), else its box; either way its origin is the box's
centre, which is what `poses` gives.
Every pedestrian walks: its body is an articulated walker (`world.actors.walker_body`) of
its box's height, with the gait amplitude `world.actors.shapes.actors.walker_amplitude` fits
to its box's length, standing on the ground at its box's centre (its body frame's origin,
the middle of its gait's sweep), its base at the hips. Its gait phase starts at
`STAND_PHASE` and advances with the distance its body moves over the ground each time it is
placed (`phase_after`), so a standing pedestrian keeps its pose and a walking one swings its
legs; it is posed (base and joints) each time it is placed.
Pedestrians are placed by station and offset from
their lane's centre like any actor; their speed is a walking speed along the lane, and the
`walk` action moves them across the road, facing where they walk.

Each actor follows a line: in a town, its own route road; on a road with an exit, an actor
that starts before the fork keeps the road the route leaves (`RoadMap.through_line`); any
other, the route. Bodies are placed with one scalar map lookup per moving actor; `poses`
(all of them, for criteria, scoring and the recording) is one vectorised map call, when
asked, with every station and offset taken on the ego's route.

In a town, each NPC car has a town driver (`world.actors.town_traffic`); the drivers share
one all-way-stop order (`world.actors.all_way_stop`), which the ego joins when it stands at
its line (`StopZones`). A driver that has arrived at its route's end is taken out of the
world (`gone`): its body and its pose far away below the ground (`GONE_XY`), no longer
minded by the others. A storyboard takes an actor out (`withdraw`: deleted, or not yet
added) and puts it back (`restore`) the same way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from pybullet_utils.bullet_client import BulletClient

from world.actors.all_way_stop import AllWayStop
from world.actors.behaviour import NpcMotion, TriggerContext
from world.actors.bodies import VEHICLES, BoxSize, body_size, vehicle_of
from world.actors.body_build import BodyBuilder
from world.actors.catalogue import CATALOGUE, DEFAULT_MODEL, VehicleClass
from world.actors.shapes.actors import vehicle_shape, walker_amplitude
from world.actors.shapes.body import Body
from world.actors.shapes.humans import phase_after
from world.actors.shapes.walker import WalkerModel, walker_model, walker_pose
from world.actors.town_traffic import STOP_MARGIN, STOP_SPEED, Others, StopZones, TownDriver
from world.actors.walker_body import pose_walker
from world.hdmap import Manoeuvre, RoadMap
from world.map.road import build_road_map
from world.map.signals import route_signals
from world.scene.collision import CollisionShapes
from world.spec import ActorSpec, ActorType

EGO = "ego"  # the ego's key in the all-way-stop order
GONE_XY = (1.0e5, 1.0e5)  # [m] where an NPC that has left the town is (below the ground)
STAND_PHASE = 0.25  # [-] a pedestrian's gait phase before it walks: the hips straight, the
#   legs side by side (the right knee bent as in mid-swing)


COLOURS = {  # [-] RGBA
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
    stations: NDArray[np.float64]  # [m] (N,) station of each centre on the ego's route
    offsets: NDArray[np.float64]  # [m] (N,) lateral offset from the route's reference line
    # [m/s] (N,) vehicles: along their lane; pedestrians: walking speed over ground (a
    # crossing's lateral motion included)
    speeds: NDArray[np.float64]
    accels: NDArray[np.float64]  # [m/s^2] (N,) rate of change of `speeds`, signed
    # each vehicle's catalogue class, None for a pedestrian or an obstacle; () (poses made
    # by hand in tests): as the type's default model, see `truth_class`
    classes: tuple[VehicleClass | None, ...] = ()

    def truth_class(self, i: int) -> VehicleClass | None:
        """The catalogue class of actor `i` (None: not a vehicle)."""
        if self.classes:
            return self.classes[i]
        kind = self.kinds[i]
        return CATALOGUE[DEFAULT_MODEL[kind.value]].cls if kind in VEHICLES else None


def actor_shape(spec: ActorSpec, size: BoxSize) -> Body | None:
    """The rigid shape of an actor's body whose box is `size` (None: the box itself, or a
    walker: `actor_walker`)."""
    model = vehicle_of(spec)
    if model is not None:
        return vehicle_shape(model.name, size.length, size.width)
    return None


def actor_walker(spec: ActorSpec, size: BoxSize) -> WalkerModel | None:
    """The articulated walker that is a pedestrian's body whose box is `size`: the box's
    height, its gait's amplitude fitted to the box's length (`walker_amplitude`; None: not a
    pedestrian)."""
    if spec.type is not ActorType.PEDESTRIAN:
        return None
    amplitude = walker_amplitude(size.length, size.width, size.height)
    return walker_model(size.height, size.width, amplitude)


class ActorSet:
    """All scripted actors of a world."""

    def __init__(self, client: BulletClient, road: RoadMap, specs: tuple[ActorSpec, ...],
                 shapes: CollisionShapes | None = None) -> None:
        """`shapes` keeps the bodies' collision boxes (a book of its own when None)."""
        self._c = client
        self._shapes = CollisionShapes() if shapes is None else shapes
        self._reset_pose = client.resetBasePositionAndOrientation  # bound once: hot path
        self._road = road
        self.specs = specs
        # in a town each actor drives its own route road; on a road, the route
        self._maps = [road if a.road is None else build_road_map(a.road) for a in specs]
        self._own = np.array([a.road is not None for a in specs], dtype=bool)
        self.motions: list[NpcMotion] = []
        for spec, own_map in zip(specs, self._maps, strict=True):
            lane = own_map.lane(spec.lane)
            offset = float(lane.offset_at(spec.s)) + spec.offset
            self.motions.append(
                NpcMotion(spec.s, offset, spec.speed,
                          -lane.direction if spec.against else lane.direction, spec.actions,
                          lane=spec.lane, pedestrian=spec.type is ActorType.PEDESTRIAN,
                          facing=spec.facing)
            )
        sizes = [body_size(a) for a in specs]
        builder = BodyBuilder(client, self._shapes)
        self._builder = builder  # keeps the visuals' mesh files while the client draws
        self.shapes = [actor_shape(a, size) for a, size in zip(specs, sizes, strict=True)]
        self.walkers = [actor_walker(a, size) for a, size in zip(specs, sizes, strict=True)]
        self.bodies = [
            builder.walker(walker) if walker is not None
            else builder.box((size.length / 2, size.width / 2, size.height / 2), COLOURS[a.type])
            if shape is None else builder.shaped(shape, size.height, COLOURS[a.type])
            for a, size, shape, walker in zip(specs, sizes, self.shapes, self.walkers,
                                              strict=True)]
        self.phases = [STAND_PHASE] * len(specs)  # [-] each walker's gait phase (0 to 1)
        self.lengths = np.array([size.length for size in sizes])
        self.half_sizes = np.array(
            [[size.length / 2, size.width / 2, size.height / 2] for size in sizes]
        ).reshape(-1, 3)
        self.order = AllWayStop()  # whose turn at the town's all-way stops (the truth)
        self._drivers = [
            TownDriver(own_map, route_signals(a.road, own_map), size.length / 2, a.id,
                       self.order)
            if a.road is not None and a.type in VEHICLES else None
            for a, own_map, size in zip(specs, self._maps, sizes, strict=True)
        ]
        self._ego_zones = StopZones(road) if any(d is not None for d in self._drivers) else None
        self._ego_at: tuple[int, int] | None = None  # the all-way stop the ego stands at
        self._ego_prev: tuple[float, float] | None = None  # [m] its centre a step ago
        self.gone = np.zeros(len(specs), dtype=bool)  # arrived town drivers, out of the world
        self._last_speed = self._speeds()  # [m/s] before the last step
        self._dt = 1.0  # [s] the last step
        self._ids = tuple(a.id for a in specs)
        self._kinds = tuple(a.type for a in specs)
        self._classes = tuple(m.cls if (m := vehicle_of(a)) is not None else None
                              for a in specs)
        # [rad] an oncoming actor's body faces against the route
        self._flip_list = [math.pi if m.direction < 0 else 0.0 for m in self.motions]
        self._flip = np.array(self._flip_list)
        self._heights = self.half_sizes[:, 2].tolist()  # [m] box centre above the ground
        # traffic on the road before the route's first exit keeps that road (it goes on
        # straight from the fork, `RoadMap.through_line`); the rest follows the route
        self._fork = road.exits[0].s if road.exits else math.inf
        self._through = np.array([a.s < self._fork and a.road is None for a in specs],
                                 dtype=bool)
        self._lines = [road.through_line if through else own_map.line
                       for through, own_map in zip(self._through.tolist(), self._maps,
                                                   strict=True)]
        self.town_drivers = any(d is not None for d in self._drivers)
        self._xy = np.zeros((len(specs), 2))  # [m] each body's centre as last placed
        self._xy_prev = self._xy  # [m] ... a step before (velocities over ground)
        self._poses: ActorPoses | None = None
        self._place(force=True)

    def lane_offset(self, lane: int, s: float) -> float:
        """[m] offset of a route lane's centre at s (the actors on the route's road)."""
        return float(self._road.lane(lane).offset_at(s))

    def gaps(self, ego_s: float, ego_length: float,
             ego_xy: tuple[float, float] | None = None) -> NDArray[np.float64]:
        """[m] (N,) bumper-to-bumper distance of each actor to the ego: along the route, or
        for an actor on its own town route (given `ego_xy`), centre to centre less both
        half lengths."""
        s = np.array([m.s for m in self.motions])
        gaps = np.maximum(0.0, np.abs(s - ego_s) - (self.lengths + ego_length) / 2)
        if ego_xy is not None and self._own.any():
            apart = np.hypot(self._xy[:, 0] - ego_xy[0], self._xy[:, 1] - ego_xy[1])
            direct = np.maximum(0.0, apart - (self.lengths + ego_length) / 2)
            gaps = np.where(self._own, direct, gaps)
        return gaps

    def fire_triggers(self, t: float, ego_s: float, ego_length: float,
                      ego_xy: tuple[float, float] | None = None) -> list[tuple[str, int]]:
        """Start the actions whose triggers hold; returns (actor id, action index) started."""
        started = []
        for spec, motion, gap, own_map in zip(
            self.specs, self.motions, self.gaps(ego_s, ego_length, ego_xy), self._maps,
            strict=True,
        ):
            ctx = TriggerContext(t=t, ego_s=ego_s, gap=float(gap))

            def lane_offset(lane: int, s: float, m: RoadMap = own_map) -> float:
                return float(m.lane(lane).offset_at(s))

            started += [(spec.id, i) for i in motion.fire_due(ctx, lane_offset)]
        return started

    def step(self, t: float, dt: float, ego: tuple[float, float, float] | None = None,
             ego_s: float | None = None) -> None:
        """Advance every motion by dt [s] and move the moving bodies to their new poses.
        `ego`: (x, y, half length) of the ego, for town drivers to keep their distance;
        `ego_s` [m] its centre's station on its route (where it turns next)."""
        self._last_speed = self._speeds()
        self._dt = dt
        self._cap_town_drivers(t, dt, ego, ego_s)
        for motion, line, gone in zip(self.motions, self._lines, self.gone.tolist(),
                                      strict=True):
            if not gone:  # out of the world: held where it left, at its speed
                motion.step(t, dt, line.curvature_one(motion.s))
        self._poses = None
        self._place(force=False)

    def _cap_town_drivers(self, t: float, dt: float, ego: tuple[float, float, float] | None,
                          ego_s: float | None) -> None:
        """Each town driver's speed cap from its rules and the other vehicles' centres,
        velocities (those over the last step) and turns at their next junctions; the ego's
        place in the all-way-stop order."""
        if not self._own.any():
            return
        vehicles = np.array([k in VEHICLES for k in self._kinds]) & ~self.gone
        xy, half = self._xy[vehicles], self.half_sizes[vehicles, 0]
        across = np.array([d is not None and d.turns_across_next() for d in self._drivers],
                          dtype=bool)[vehicles]
        velocity = (self._xy - self._xy_prev)[vehicles] / dt
        self._xy_prev = self._xy.copy()
        if ego is not None:
            prev = self._ego_prev if self._ego_prev is not None else ego[:2]
            ego_v = ((ego[0] - prev[0]) / dt, (ego[1] - prev[1]) / dt)
            self._ego_prev = (ego[0], ego[1])
            self._ego_order(t, ego, math.hypot(*ego_v))
            xy = np.vstack([xy, [ego[:2]]])
            velocity = np.vstack([velocity, [ego_v]])
            half = np.append(half, ego[2])
            across = np.append(across, ego_s is not None and
                               self._ego_turns_across(ego_s + ego[2]))
        index = np.cumsum(vehicles) - 1  # row of each vehicle actor in xy
        for i, (driver, motion) in enumerate(zip(self._drivers, self.motions, strict=True)):
            if driver is None or self.gone[i]:
                continue
            others = np.ones(len(xy), dtype=bool)
            others[index[i]] = False
            motion.cap = driver.speed_cap(
                t, motion.s, motion.speed,
                Others(xy[others], velocity[others], half[others], across[others]))
            if driver.arrived:
                self._leave(i)

    def _ego_turns_across(self, front: float) -> bool:
        """Whether the ego's route turns left or makes a U-turn at the first junction whose
        stop line its front bumper (station `front` [m]) is not over."""
        j = next((j for j in self._road.junctions if j.s_stop > front - STOP_MARGIN), None)
        return j is not None and j.manoeuvre in (Manoeuvre.LEFT, Manoeuvre.U_TURN)

    def _ego_order(self, t: float, ego: tuple[float, float, float], speed: float) -> None:
        """The ego arrives at an all-way stop when it stands at its line (slower than the
        stack's stood speed), and leaves the order when it moves off (faster than an NPC's
        stopped speed) or is no longer at the line: the NPCs mind its turn as any other's."""
        assert self._ego_zones is not None
        if self._ego_at is not None:
            still = self._ego_zones.at_line(ego[:2], ego[2], speed, STOP_SPEED)
            if still is None or still.index != self._ego_at:
                self.order.leave(self._ego_at, EGO)
                self._ego_at = None
        if self._ego_at is None:
            at = self._ego_zones.at_line(ego[:2], ego[2], speed)
            if at is not None:
                self.order.arrive(at.index, EGO, at.heading, t)
                self._ego_at = at.index

    def _leave(self, i: int) -> None:
        """Take actor i out of the world: it has arrived at its route's end."""
        self.motions[i].speed = 0.0
        self.motions[i].cap = 0.0
        self.withdraw(i)

    def withdraw(self, i: int) -> None:
        """Take actor i out of the world (`gone`): its body far away below the ground (no
        contacts, unseen), its motion held (not stepped) until it is `restore`d."""
        self.gone[i] = True
        self._xy[i] = GONE_XY
        self._poses = None
        self._reset_pose(self.bodies[i], (*GONE_XY, -10.0), (0.0, 0.0, 0.0, 1.0))

    def restore(self, i: int) -> None:
        """Put actor i back into the world where its motion is (placed at the next step,
        or now when its motion is moved there first)."""
        self.gone[i] = False
        self.motions[i].jumped = True
        self._poses = None
        self._place(force=False)

    def _speeds(self) -> NDArray[np.float64]:
        """[m/s] (N,) `ActorPoses.speeds` now."""
        return np.array([m.ground_speed if m.pedestrian else m.speed for m in self.motions],
                        dtype=np.float64)

    @property
    def accels(self) -> NDArray[np.float64]:
        """[m/s^2] (N,) each actor's acceleration (of `ActorPoses.speeds`) over the last step."""
        out: NDArray[np.float64] = (self._speeds() - self._last_speed) / self._dt
        return out

    @property
    def poses(self) -> ActorPoses:
        """Ground truth of every actor now (computed when asked, once per step)."""
        if self._poses is None:
            self._poses = self._compute_poses()
        return self._poses

    def _compute_poses(self) -> ActorPoses:
        m = self.motions
        s = np.array([x.s for x in m])
        offsets = np.array([x.offset for x in m])
        x, y, heading = self._road.line.pose(s, offsets)  # offsets are from the reference line
        through = self._through & (s > self._fork)  # on the road the route left by its exit
        if through.any():
            x[through], y[through], heading[through] = self._road.through_line.pose(
                s[through], offsets[through])
        for i in np.flatnonzero(self._own):  # on its own town route
            x[i], y[i], heading[i] = self._lines[i].pose_one(float(s[i]), float(offsets[i]))
        through = through | self._own
        if through.any():
            # the truth along the route, where criteria look for vehicles: projected
            s = s.copy()
            s[through], offsets[through] = self._road.local_coordinates(
                np.column_stack([x[through], y[through]]))
        yaws = heading + self._flip + np.array([x.heading_offset for x in m])
        centres = np.column_stack([x, y, self.half_sizes[:, 2]]) if m else np.zeros((0, 3))
        if self.gone.any():  # left the town: far away, below the ground
            centres[self.gone] = (*GONE_XY, -10.0)
            s[self.gone], offsets[self.gone] = self._road.local_coordinates(
                np.array([GONE_XY]))
        return ActorPoses(
            ids=self._ids,
            kinds=self._kinds,
            classes=self._classes,
            centres=centres,
            yaws=yaws,
            half_sizes=self.half_sizes,
            stations=s,
            offsets=offsets,
            speeds=self._speeds(),
            accels=self.accels,
        )

    def _place(self, force: bool) -> None:
        """Move the bodies of the actors that move (all of them with `force`): one scalar
        map lookup each, the hot path of the NPCs."""
        for i, (body, m, flip, z, line, gone) in enumerate(zip(
                self.bodies, self.motions, self._flip_list, self._heights, self._lines,
                self.gone.tolist(), strict=True)):
            if gone:
                continue
            if force or m.speed != 0.0 or m.lateral_speed != 0.0 or m.jumped:
                x, y, heading = line.pose_one(m.s, m.offset)
                yaw = heading + flip + m.heading_offset
                walker = self.walkers[i]
                if walker is not None:
                    self._pose_walker(i, walker, x, y, yaw, walked=not (force or m.jumped))
                else:
                    half = 0.5 * yaw
                    self._reset_pose(body, (x, y, z), (0.0, 0.0, math.sin(half), math.cos(half)))
                m.jumped = False
                self._xy[i] = (x, y)

    def _pose_walker(self, i: int, walker: WalkerModel, x: float, y: float, yaw: float,
                     walked: bool) -> None:
        """Pose walker `i` with its body frame at (`x`, `y`) [m] on the ground heading `yaw`
        [rad]; `walked`: it walked there from where it was last placed, its phase advanced by
        that distance over the ground (not after a jump: placed first, restored, moved)."""
        if walked:
            prev = self._xy[i]
            distance = math.hypot(x - float(prev[0]), y - float(prev[1]))
            self.phases[i] = phase_after(self.phases[i], distance, walker.height,
                                         walker.amplitude)
        pose_walker(self._c, self.bodies[i], x, y, yaw,
                    walker_pose(walker.height, self.phases[i], walker.width, walker.amplitude))

    def joints(self) -> tuple[tuple[float, ...], ...]:
        """[rad] each actor's body's joint angles now, in joint order (() for a rigid body)."""
        out = []
        for body, walker in zip(self.bodies, self.walkers, strict=True):
            n = 0 if walker is None else len(walker.links)
            out.append(tuple(float(j[0]) for j in self._c.getJointStates(body, list(range(n))))
                       if n else ())
        return tuple(out)

    def set_joints(self, joints: tuple[tuple[float, ...], ...]) -> None:
        """Turn each actor's body's joints to `joints` (as `joints()` gave them)."""
        for body, angles in zip(self.bodies, joints, strict=True):
            if angles:
                self._c.resetJointStatesMultiDof(body, list(range(len(angles))),
                                                 [[a] for a in angles])
