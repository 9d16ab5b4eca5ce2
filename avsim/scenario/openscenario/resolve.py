"""Where an OpenSCENARIO position is, on the file's OpenDRIVE roads: the map-frame pose of
an entity's reference point.

The roads are linked end to end into one (`world.map.opendrive.chain`): a lane or road
position's (roadId, s) is the merged road's station `starts[roadId] + s`, s within that
road's own length; an unknown roadId is a `PositionError`. Road coordinates (s along the
merged road's reference line, t left +) come from the roads' exact geometry
(`world.map.opendrive`); a lane position's t is its lane's centre plus the offset.
Relative positions start from the referenced entity's reference point (`Pose`): a relative
lane position moves `d_lane` lanes (OpenDRIVE ids, the centre lane 0 skipped) from the lane
the entity is in and `ds` along the reference line (`ds_lane` along the lane's centre);
a relative road position adds (ds, dt) to its road coordinates; a relative world position
adds (dx, dy) in map axes, a relative object position in the entity's axes. Relative
positions work on the merged road, so they run on across a road's end into the next road.

A trajectory position is `s` along the trajectory's sampled shape (`sampling`) and `t` to
its left, headed along it.

The heading of a position on the road is the road's at s (right-hand lanes travel along it,
left-hand lanes against it) unless an orientation says otherwise: a relative orientation
adds its h, an absolute one replaces it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from avsim.scenario.openscenario.model import (
    LanePosition,
    Orientation,
    Position,
    RelativeLanePosition,
    RelativeObjectPosition,
    RelativeRoadPosition,
    RelativeWorldPosition,
    RoadPosition,
    TrajectoryPosition,
    WorldPosition,
)
from world.map.opendrive import Chain, lane_borders


@dataclass(frozen=True, slots=True)
class Pose:
    """A reference point's pose, map frame."""

    x: float  # [m]
    y: float  # [m]
    heading: float  # [rad]
    lane_id: int | None = None  # the OpenDRIVE lane a lane position names: the entity's lane,
    #   as esmini keeps it, even where the offset puts the point over its border


class PositionError(ValueError):
    """A position that is not on the road (a lane that does not exist there, ...)."""


class UnplacedError(PositionError):
    """A relative position whose entity has no position yet."""


class Resolver:
    """Positions on the OpenDRIVE roads linked end to end (module doc)."""

    def __init__(self, chain: Chain) -> None:
        self.chain = chain
        self.road = chain.road  # the merged road

    def station(self, road_id: str, s: float) -> float:
        """[m] the merged road's station of (road `road_id`, its own s); `PositionError` if
        the file has no such road or s is off it."""
        try:
            span = self.chain.span(road_id)
        except KeyError:
            ids = ", ".join(sp.road_id for sp in self.chain.spans)
            raise PositionError(f"no road {road_id} in the OpenDRIVE file (roads: {ids})"
                                ) from None
        if not 0.0 <= s <= span.length + 1e-6:
            raise PositionError(f"s = {s:g} m is off road {road_id} (0 to {span.length:g} m)")
        return span.start + s

    def road_coordinates(self, x: float, y: float) -> tuple[float, float]:
        """([m] s, [m] t) of a map point on the road (exact projection)."""
        s, t = self.road.plan_view.project(np.array([[x, y]]))
        return float(s[0]), float(t[0])

    def lane_id(self, s: float, t: float) -> int | None:
        """The OpenDRIVE lane at road coordinates (s, t) (None: outside every lane)."""
        for lane_id, (inner, outer) in lane_borders(self.road, s).items():
            lo, hi = sorted((inner, outer))
            if lane_id != 0 and lo <= t < hi:
                return lane_id
        return None

    def lane_t(self, lane_id: int, s: float) -> float:
        """[m] the centre of lane `lane_id` at s (the merged road's station)."""
        borders = lane_borders(self.road, s)
        if lane_id == 0 or lane_id not in borders:
            road_id, own_s = self.chain.locate(s)
            raise PositionError(f"road {road_id} has no lane {lane_id} at s = {own_s:g} m")
        inner, outer = borders[lane_id]
        return 0.5 * (inner + outer)

    def road_pose(self, s: float, t: float, lane_id: int | None,
                  orientation: Orientation | None) -> Pose:
        """The pose at the merged road's coordinates (s, t), headed along the lane's travel
        (module doc)."""
        if not 0.0 <= s <= self.road.length + 1e-6:
            raise PositionError(f"s = {s:g} m is off road {self.road.id} "
                                f"(0 to {self.road.length:g} m)")
        x, y, h = self.road.plan_view.pose(np.array([s]))
        heading = float(h[0])
        px, py = float(x[0]) - t * math.sin(heading), float(y[0]) + t * math.cos(heading)
        against = lane_id is not None and (lane_id > 0) == (self.road.rule == "RHT")
        travel = heading + (math.pi if against else 0.0)
        return Pose(px, py, _oriented(travel, orientation), lane_id)

    def resolve(self, position: Position, entities: Mapping[str, Pose]) -> Pose:
        """The map-frame pose of `position`; relative ones refer to `entities` (module doc)."""
        if isinstance(position, WorldPosition):
            return Pose(position.x, position.y, position.h if position.h is not None else 0.0)
        if isinstance(position, LanePosition):
            lane_id = int(position.lane_id)
            s = self.station(position.road_id, position.s)
            t = self.lane_t(lane_id, s) + position.offset
            return self.road_pose(s, t, lane_id, position.orientation)
        if isinstance(position, RoadPosition):
            s = self.station(position.road_id, position.s)
            return self.road_pose(s, position.t, None, position.orientation)
        if isinstance(position, TrajectoryPosition):
            return self._on_trajectory(position, entities)
        base = _entity(entities, position.entity)
        if isinstance(position, RelativeWorldPosition):
            return Pose(base.x + position.dx, base.y + position.dy,
                        _oriented(base.heading, position.orientation))
        if isinstance(position, RelativeObjectPosition):
            c, s = math.cos(base.heading), math.sin(base.heading)
            return Pose(base.x + c * position.dx - s * position.dy,
                        base.y + s * position.dx + c * position.dy,
                        _oriented(base.heading, position.orientation))
        s0, t0 = self.road_coordinates(base.x, base.y)
        if isinstance(position, RelativeRoadPosition):
            return self.road_pose(s0 + position.ds, t0 + position.dt, None,
                                  position.orientation)
        return self._relative_lane(position, s0, t0)

    def _on_trajectory(self, position: TrajectoryPosition,
                       entities: Mapping[str, Pose]) -> Pose:
        # the sampler resolves the trajectory's own positions through this resolver
        from avsim.scenario.openscenario.sampling import sample

        shape = position.trajectory.shape
        pose = sample(shape, lambda p: self.resolve(p, entities)).at(position.s, position.t)
        return Pose(pose.x, pose.y, _oriented(pose.heading, position.orientation))

    def _relative_lane(self, position: RelativeLanePosition, s0: float, t0: float) -> Pose:
        lane0 = self.lane_id(s0, t0)
        if lane0 is None:
            raise PositionError(f"entity {position.entity} is in no lane (s = {s0:g} m, "
                                f"t = {t0:g} m)")
        lane_id = shift_lane(lane0, position.d_lane)
        if position.ds is not None:
            s = s0 + position.ds
        else:  # along the lane's centre: the reference line's station moves less outside
            k = float(self.road.plan_view.curvature(np.array([s0]))[0])
            s = s0 + (position.ds_lane or 0.0) / max(1.0 - k * self.lane_t(lane_id, s0), 1e-3)
        t = self.lane_t(lane_id, s) + position.offset
        return self.road_pose(s, t, lane_id, position.orientation)


def shift_lane(lane_id: int, d_lane: int) -> int:
    """The OpenDRIVE lane id `d_lane` lanes to the left (+) of `lane_id` (0 skipped)."""
    out = lane_id + d_lane
    if lane_id < 0 <= out or out <= 0 < lane_id:
        out += 1 if d_lane > 0 else -1
    return out


def _entity(entities: Mapping[str, Pose], name: str) -> Pose:
    try:
        return entities[name]
    except KeyError:
        raise UnplacedError(f"entity {name} has no position yet") from None


def _oriented(heading: float, orientation: Orientation | None) -> float:
    if orientation is None:
        return heading
    if orientation.type == "absolute":
        return orientation.h
    return heading + orientation.h
