"""The storyboard's snapshot of the world's truth (`Snapshot`), step after step.

Each entity's reference point is its body centre moved back along its heading by its
`centre_ahead` (`StoryProgram`): the car under test's rear axle, the file's bounding box
reference point for the others (and for a scripted car under test, whose box is then the
file's too: `StoryProgram.ego_box`). Route coordinates are projected from those points onto the
ego's route. Running figures (odometer, time at rest, off the road, beyond the road's ends)
are integrated between snapshots (an entity out of the world counts as standing where it
left: its held speed is not integrated), and accelerations and yaw rates differenced between
them (0 at the first). Collisions are judged on the boxes (`geometry.boxes_meet`), not on
the physics bodies' contacts.
"""

from __future__ import annotations

import numpy as np

from avsim.run.storyboard.snapshot import EntityState, Snapshot
from avsim.scenario.openscenario.program import StoryProgram
from world.hdmap import RoadMap
from world.spec import ActorType
from world.world import World

AT_REST = 0.01  # [m/s] slower than this counts as standing still
CATEGORIES = {ActorType.CAR: "vehicle", ActorType.TRUCK: "vehicle",
              ActorType.PEDESTRIAN: "pedestrian", ActorType.OBSTACLE: "miscellaneous"}


class TruthTracker:
    """Snapshots of one world for one storyboard (module doc)."""

    def __init__(self, program: StoryProgram, world: World) -> None:
        self.program = program
        self.world = world
        self.road: RoadMap = world.road
        self.names = (program.ego, *(name for name, _ in program.actors))
        ahead = dict(program.centre_ahead)
        self.ahead = np.array([ahead[n] for n in self.names])
        g = world.ego.geometry
        kinds = [world.actors.specs[i].type for _, i in program.actors]
        self.categories = {program.ego: "vehicle"} | {
            name: CATEGORIES[kind] for (name, _), kind in zip(program.actors, kinds, strict=True)}
        sizes = world.actors.half_sizes * 2.0
        length, width = program.ego_box or (g.body_length, g.body_width)
        self.lengths = np.concatenate([[length], sizes[:, 0]])
        self.widths = np.concatenate([[width], sizes[:, 1]])
        n = len(self.names)
        self.odometer = np.zeros(n)
        self.standing = np.zeros(n)
        self.off_road = np.zeros(n)
        self.beyond = np.zeros(n)
        self._t: float | None = None
        self._speed = np.zeros(n)  # [m/s] at the previous snapshot
        self._yaw = np.zeros(n)  # [rad] at the previous snapshot

    def snapshot(self) -> Snapshot:
        """The truth now."""
        w = self.world
        t = w.t
        dt = 0.0 if self._t is None else t - self._t
        self._t = t
        truth = w.ego_truth
        poses = w.actors.poses
        order = [i for _, i in self.program.actors]
        cx = np.concatenate([[truth.position[0]], poses.centres[order, 0]])
        cy = np.concatenate([[truth.position[1]], poses.centres[order, 1]])
        yaw = np.concatenate([[truth.yaw], poses.yaws[order]])
        speed = np.concatenate([[truth.speed], poses.speeds[order]])
        x = cx - self.ahead * np.cos(yaw)
        y = cy - self.ahead * np.sin(yaw)
        s, d = self.road.local_coordinates(np.column_stack([x, y]))
        present = np.concatenate([[True], ~w.actors.gone[order]])
        self._integrate(dt, speed, s, d, present)
        acc, yaw_rate = self._rates(dt, speed, yaw)
        route_heading = self.road.heading_at(s)
        entities = {
            name: EntityState(
                name=name, x=float(x[k]), y=float(y[k]), heading=float(yaw[k]),
                speed=float(speed[k]), s=float(s[k]), offset=float(d[k]),
                lane=self.road.lane_of(float(s[k]), float(d[k]))[0],
                route_heading=float(route_heading[k]), length=float(self.lengths[k]),
                width=float(self.widths[k]), centre_ahead=float(self.ahead[k]),
                odometer=float(self.odometer[k]), standing_for=float(self.standing[k]),
                off_road_for=float(self.off_road[k]), end_of_road_for=float(self.beyond[k]),
                acceleration=float(acc[k]), yaw_rate=float(yaw_rate[k]))
            for k, name in enumerate(self.names)}
        gone = w.actors.gone
        inactive = frozenset(name for name, i in self.program.actors if gone[i])
        return Snapshot(t, entities, self.categories, inactive)

    def _rates(self, dt: float, speed: np.ndarray,
               yaw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """([m/s²] d speed / dt, [rad/s] d yaw / dt wrapped to a half turn) since the last
        snapshot; zeros at the first."""
        if dt > 0.0:
            acc = (speed - self._speed) / dt
            turn = np.angle(np.exp(1j * (yaw - self._yaw))) / dt
        else:
            acc, turn = np.zeros_like(speed), np.zeros_like(speed)
        self._speed, self._yaw = speed.copy(), yaw.copy()
        return acc, turn

    def _integrate(self, dt: float, speed: np.ndarray, s: np.ndarray, d: np.ndarray,
                   present: np.ndarray) -> None:
        """Advance the running figures by dt [s]; an entity not `present` (out of the world)
        counts as standing where it left."""
        speed = np.where(present, speed, 0.0)
        self.odometer += np.abs(speed) * dt
        self.standing = np.where(np.abs(speed) < AT_REST, self.standing + dt, 0.0)
        right, left = self.road.paved_edges(s)
        off = (d < right) | (d > left)
        self.off_road = np.where(off, self.off_road + dt, 0.0)
        beyond = (s <= 0.0) | (s >= self.road.length)
        self.beyond = np.where(beyond, self.beyond + dt, 0.0)

