"""An OpenSCENARIO private action as a command to one actor's motion
(`world.actors.profiles`), from the truth at the moment it starts.

- SpeedAction: a speed transition from the actor's speed to the target (absolute, or the
  referenced entity's speed now plus a delta / times a factor), shaped and timed by its
  dynamics (`profiles`: a rate is the peak acceleration); a continuous relative target
  keeps following the entity's speed afterwards (`Follow`).
- LaneChangeAction: a lateral transition to the target lane's centre (plus its target
  offset); the target lane is an OpenDRIVE id, or lanes to the left of an entity's lane; a
  rate is the peak lateral speed.
- LaneOffsetAction: a lateral transition to an offset from the actor's lane centre (or to
  an entity's lateral position plus a value, to its left when it drives along the route:
  esmini's reading of a relative target), timed by its peak lateral acceleration
  (`LANE_OFFSET_ACCEL` when the file gives none): sinusoidal T = pi sqrt(d / 2a), cubic
  T = sqrt(6 d / a), linear and step as fast as that acceleration allows from rest to
  rest, T = 2 sqrt(d / a).
- FollowTrajectoryAction: a polyline of resolved positions, in route coordinates of the
  body centre; timed when the action has a time reference (vertex time x scale + offset,
  plus the start time for the relative domain), else at the actor's speed.
- LongitudinalDistanceAction: keeps a distance (or a time gap at the referenced entity's
  speed) ahead of or behind the entity along the route (`Follow`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from avsim.run.storyboard.snapshot import EntityState, Snapshot
from avsim.scenario.openscenario.model import (
    AbsoluteTargetLane,
    AbsoluteTargetLaneOffset,
    AbsoluteTargetSpeed,
    FollowTrajectoryAction,
    LaneChangeAction,
    LaneOffsetAction,
    LongitudinalDistanceAction,
    RelativeTargetSpeed,
    SpeedAction,
    TransitionDynamics,
)
from avsim.scenario.openscenario.resolve import Pose, Resolver
from world.actors.profiles import (
    LateralCommand,
    PathCommand,
    Shape,
    SpeedCommand,
    TrackCommand,
    Transition,
    span_by_rate,
    speed_span_by_distance,
)
from world.hdmap import RoadMap

LANE_OFFSET_ACCEL = 0.5  # [m/s^2] a lane offset's peak lateral acceleration, if not given
GAP_GAIN = 0.5  # [1/s] a distance keeper's speed correction per metre of gap error
DISTANCE_ACCEL = 4.0  # [m/s^2] a distance keeper's limits where the file gives none
GAP_REACHED = 0.2  # [m] a non-continuous distance action ends within this of its gap ...
SPEED_MATCHED = 0.1  # [m/s] ... at the entity's speed within this


@dataclass(frozen=True, slots=True)
class Follow:
    """A command the director refreshes every step from the truth: a continuous relative
    speed, or a distance to keep."""

    tag: str
    entity: str  # the one it acts on
    action: SpeedAction | LongitudinalDistanceAction
    after: float = 0.0  # [s] renewed from this time on (a relative speed: once its
    #   transition to the entity's speed is done)


class Commands:
    """Builds commands on one route (module doc)."""

    def __init__(self, road: RoadMap, resolver: Resolver, lane_ids: tuple[int, ...]) -> None:
        self.road = road
        self.resolver = resolver
        self.lane_ids = lane_ids

    def speed(self, tag: str, action: SpeedAction, me: EntityState,
              snap: Snapshot) -> SpeedCommand:
        """A speed transition; a continuous one never reports finished."""
        target = _speed_target(action, snap)
        span = _speed_span(action.dynamics, me.speed, target)
        continuous = isinstance(action.target, RelativeTargetSpeed) and action.target.continuous
        return SpeedCommand(tag, Transition(me.speed, target, Shape(action.dynamics.shape),
                                            span), snap.time, continuous=continuous)

    def lane_change(self, tag: str, action: LaneChangeAction, me: EntityState,
                    centre_offset: float, snap: Snapshot) -> LateralCommand:
        """`centre_offset`: the actor's body centre offset from the reference line [m]."""
        target = action.target
        if isinstance(target, AbsoluteTargetLane):
            lane_id = int(target.value)
            if lane_id not in self.lane_ids:
                raise ValueError(f"lane {lane_id} is not a lane of the route")
            lane = self.lane_ids.index(lane_id)
        else:
            ref = snap.entities[target.entity]
            if ref.lane is None:
                raise ValueError(f"entity {target.entity} is in no lane")
            lane = ref.lane + target.value
        if not 0 <= lane < self.road.lanes_at(me.s):
            raise ValueError(f"the target lane (route lane {lane}) does not exist here")
        goal = float(self.road.lane(lane).offset_at(me.s)) + (action.target_lane_offset or 0.0)
        d = action.dynamics
        shape = Shape(d.shape)
        if d.dimension == "distance":
            return LateralCommand(tag, Transition(centre_offset, goal, shape, d.value),
                                  snap.time, me.s, by_distance=True, lane=lane)
        span = d.value if d.dimension == "time" else span_by_rate(shape, goal - centre_offset,
                                                                   d.value)
        return LateralCommand(tag, Transition(centre_offset, goal, shape, span), snap.time,
                              me.s, lane=lane)

    def lane_offset(self, tag: str, action: LaneOffsetAction, me: EntityState,
                    centre_offset: float, snap: Snapshot) -> LateralCommand:
        target = action.target
        lane = me.lane if me.lane is not None else 0
        centre = float(self.road.lane(lane).offset_at(me.s))
        if isinstance(target, AbsoluteTargetLaneOffset):
            goal = centre + target.value
        else:
            ref = snap.entities[target.entity]
            along = math.cos(ref.heading - ref.route_heading) >= 0.0
            goal = ref.offset + (target.value if along else -target.value)
        accel = action.dynamics.max_lateral_acc or LANE_OFFSET_ACCEL
        shape = Shape(action.dynamics.shape)
        span = _offset_span(shape, abs(goal - centre_offset), accel)
        return LateralCommand(tag, Transition(centre_offset, goal, shape, span), snap.time,
                              me.s)

    def trajectory(self, tag: str, action: FollowTrajectoryAction, me: EntityState,
                   snap: Snapshot) -> PathCommand:
        poses = poses_of(snap)
        points = [self.resolver.resolve(v.position, poses) for v in
                  action.trajectory.shape.vertices]
        ahead = me.centre_ahead
        xy = [(p.x + ahead * math.cos(p.heading), p.y + ahead * math.sin(p.heading))
              for p in points]
        s, d = self.road.local_coordinates(xy)
        timing = action.time_reference
        times = None
        vertices = action.trajectory.shape.vertices
        if timing is not None and all(v.time is not None for v in vertices):
            base = snap.time if timing.domain == "relative" else 0.0
            times = tuple(base + (v.time or 0.0) * timing.scale + timing.offset
                          for v in vertices)
        return PathCommand(tag, tuple(float(x) for x in s), tuple(float(x) for x in d), times)

    def follow(self, follow: Follow, me: EntityState, snap: Snapshot,
               max_speed: float) -> tuple[TrackCommand, bool]:
        """(the command for this step, whether the follow's goal is reached)."""
        action = follow.action
        if isinstance(action, SpeedAction):
            target = _speed_target(action, snap)
            return TrackCommand(follow.tag, target, DISTANCE_ACCEL, DISTANCE_ACCEL,
                                max_speed), False
        ref = snap.entities[action.entity]
        want = action.distance if action.distance is not None else (
            (action.time_gap or 0.0) * max(ref.speed, 0.0))
        sign = -1.0 if action.displacement == "trailingReferencedEntity" else 1.0
        gap = sign * (me.s - ref.s)
        if action.freespace:
            gap -= 0.5 * (me.length + ref.length)
        target = max(0.0, ref.speed + GAP_GAIN * sign * (gap - want))
        c = action.constraints
        accel = c.max_acceleration if c is not None and c.max_acceleration else DISTANCE_ACCEL
        decel = c.max_deceleration if c is not None and c.max_deceleration else DISTANCE_ACCEL
        top = c.max_speed if c is not None and c.max_speed else max_speed
        reached = abs(gap - want) < GAP_REACHED and abs(me.speed - ref.speed) < SPEED_MATCHED
        return TrackCommand(follow.tag, min(target, top), accel, decel, top), reached


def poses_of(snap: Snapshot) -> dict[str, Pose]:
    """Each entity's reference point pose, as positions refer to them."""
    return {name: Pose(e.x, e.y, e.heading) for name, e in snap.entities.items()}


def _speed_target(action: SpeedAction, snap: Snapshot) -> float:
    target = action.target
    if isinstance(target, AbsoluteTargetSpeed):
        return target.value
    assert isinstance(target, RelativeTargetSpeed)
    ref = snap.entities[target.entity].speed
    return ref + target.value if target.value_type == "delta" else ref * target.value


def _speed_span(d: TransitionDynamics, start: float, target: float) -> float:
    """[s] how long a speed change takes under its dynamics (`world.actors.profiles`)."""
    shape = Shape(d.shape)
    if d.dimension == "time":
        return d.value
    if d.dimension == "distance":
        return speed_span_by_distance(start, target, d.value)
    if abs(target - start) < SPEED_MATCHED * 1e-3 or shape is Shape.STEP:
        return 0.0  # nothing to change (to rounding: an entity's speed read back)
    if d.value <= 0.0:
        raise ValueError(f"a speed change at rate {d.value:g} m/s^2 never ends")
    return span_by_rate(shape, target - start, d.value)


def _offset_span(shape: Shape, distance: float, accel: float) -> float:
    """[s] a lateral move of `distance` [m] at a peak lateral acceleration `accel` [m/s^2]."""
    if distance == 0.0:
        return 0.0
    if shape is Shape.SINUSOIDAL:
        return math.pi * math.sqrt(distance / (2.0 * accel))
    if shape is Shape.CUBIC:
        return math.sqrt(6.0 * distance / accel)
    return 2.0 * math.sqrt(distance / accel)
