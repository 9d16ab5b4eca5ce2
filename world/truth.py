"""Ground-truth queries: for criteria, perception scoring and the recording, never the stack.

Points are in the map frame [m]; the car's points are its base link origin (the centre) and
points offset from it along the body's forward and left axes in the map plane (the body's
yaw only), by the URDF's geometry: front axle `front_axle` ahead, rear axle `rear_axle`
behind, tyres `track / 2` each side.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from vehicle_urdf import CarGeometry
from world.hdmap import ReferenceLine, RoadMap
from world.spec import ActorType

if TYPE_CHECKING:  # types only: the criteria import this module, the loader them, and no
    #   scenario file is read with PyBullet loaded
    from pybullet_utils.bullet_client import BulletClient

    from world.actors.actor_set import ActorPoses
    from world.ego.body import EgoTruth


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


def route_truth(truth: EgoTruth, g: CarGeometry, line: ReferenceLine,
                near: float | None = None) -> RouteTruth:
    """Project the ego's centre, front axle and tyre patches onto the route in one call;
    `near` [m]: the centre's station a moment ago, so that a route passing the same point
    twice (a town route through a junction it crossed before) keeps the pass the car is on
    (`ReferenceLine.project`)."""
    fwd, left = body_axes(truth)
    x = np.array([0.0, g.front_axle, g.front_axle, g.front_axle, -g.rear_axle, -g.rear_axle])
    y = np.array([0.0, 0.0, g.track / 2, -g.track / 2, g.track / 2, -g.track / 2])
    points = truth.position[:2] + x[:, None] * fwd + y[:, None] * left
    s, d = line.project(points, near)
    return RouteTruth(points, s, d)


def touching(client: BulletClient, body: int, ignore: int) -> set[int]:
    """Bodies in contact with `body` now, other than `ignore` (the ground)."""
    return {int(c[2]) for c in client.getContactPoints(bodyA=body) if c[2] != ignore}


VEHICLES = frozenset({ActorType.CAR, ActorType.TRUCK})  # the actor kinds that can be ahead
ALONG = math.cos(math.radians(45.0))  # a vehicle heading within 45 deg of its lane's
#   direction travels along it (crossing or oncoming traffic does not)


@dataclass(frozen=True, slots=True)
class VehicleAhead:
    """A vehicle ahead of the ego in its lane (`vehicles_ahead`)."""

    id: str  # the actor's id
    gap: float  # [m] bumper to bumper along the route
    speed: float  # [m/s] along its lane
    accel: float  # [m/s^2] rate of change of its speed, signed


def ego_lane_edges(road: RoadMap, station: float, offset: float) -> tuple[float, float]:
    """([m] right, [m] left) offsets from the reference line of the edges of the lane the
    ego's centre (at `station`, `offset`) is in: the band of lane width that holds it, of
    the route's lanes as they lie at that station."""
    if road.cross_section_at(station).profile is not None:
        _, right, left = road.band_edges(station, offset)
        return right, left
    c0 = float(road.lane(0).offset_at(station))
    w = float(road.lane(0).width_at(station))
    band = math.floor((offset - c0 + 0.5 * w) / w)
    return c0 + (band - 0.5) * w, c0 + (band + 0.5) * w


class _LastAhead:
    """The last question put to `vehicles_ahead` and its answer: the runner's log and the
    criteria ask the same of each tick's truth (the same poses object and map, the same
    numbers bit for bit)."""

    objects: tuple[object, ...] = ()  # (poses, road), compared by identity
    numbers: tuple[str, ...] = ()  # (station, offset, ego_length) as `float.hex`
    answer: tuple[VehicleAhead, ...] = ()


def vehicles_ahead(road: RoadMap, poses: ActorPoses, station: float, offset: float,
                   ego_length: float) -> tuple[VehicleAhead, ...]:
    """`find_vehicles_ahead`, its last answer given again to the same question."""
    numbers = (float(station).hex(), float(offset).hex(), float(ego_length).hex())
    last = _LastAhead.objects
    if not (last and last[0] is poses and last[1] is road and _LastAhead.numbers == numbers):
        _LastAhead.objects, _LastAhead.numbers = (poses, road), numbers
        _LastAhead.answer = find_vehicles_ahead(road, poses, station, offset, ego_length)
    return _LastAhead.answer


def find_vehicles_ahead(road: RoadMap, poses: ActorPoses, station: float, offset: float,
                        ego_length: float) -> tuple[VehicleAhead, ...]:
    """The vehicles (cars, trucks) ahead of the ego in its lane, nearest first, from the
    truth and the map: their footprint (the box, turned by its heading relative to the
    route) overlaps, across, the lane the ego's centre is in (`ego_lane_edges`), their
    centre is ahead of the ego's along its route, and they travel along the lane (heading
    within 45 deg of it). In a town as on a road, every actor's station and offset are on
    the ego's route (`ActorPoses`). The gap is the stations' difference less the ego's half
    length and the vehicle's half extent along the route."""
    if not len(poses.ids):
        return ()
    lo, hi = ego_lane_edges(road, station, offset)
    rel = poses.yaws - np.asarray(road.heading_at(poses.stations))
    cos, sin = np.abs(np.cos(rel)), np.abs(np.sin(rel))
    half_l, half_w = poses.half_sizes[:, 0], poses.half_sizes[:, 1]
    across = half_w * cos + half_l * sin  # [m] the footprint's half extent across
    along = half_l * cos + half_w * sin
    candidates = ((poses.offsets + across > lo) & (poses.offsets - across < hi)
                  & (poses.stations > station) & (np.cos(rel) > ALONG))
    gaps = poses.stations - station - along - 0.5 * ego_length
    out = [VehicleAhead(poses.ids[i], float(gaps[i]), float(poses.speeds[i]),
                        float(poses.accels[i]))
           for i in np.flatnonzero(candidates) if poses.kinds[i] in VEHICLES]
    return tuple(sorted(out, key=lambda v: v.gap))


def time_to_collision(gap: NDArray[np.float64], ego_speed: NDArray[np.float64],
                      lead_speed: NDArray[np.float64]) -> NDArray[np.float64]:
    """[s] per tick: the gap [m] (a negative one as 0) over the closing speed
    ego_speed - lead_speed [m/s] where that is > 0; NaN where there is no lead (a NaN gap or
    lead speed) or the ego does not close on it."""
    closing = ego_speed - lead_speed
    valid = np.isfinite(gap) & np.isfinite(closing) & (closing > 0.0)
    ttc = np.full(np.shape(gap), np.nan, dtype=np.float64)
    ttc[valid] = np.maximum(gap[valid], 0.0) / closing[valid]
    return ttc
