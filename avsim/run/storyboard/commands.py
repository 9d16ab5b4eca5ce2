"""An OpenSCENARIO private action as a command to one actor's motion
(`world.actors.profiles`), from the truth at the moment it starts.

- SpeedAction: a speed transition from the actor's speed to the target (absolute, or the
  referenced entity's speed now plus a delta / times a factor), shaped and timed by its
  dynamics (`profiles`: a rate is the peak acceleration); a continuous relative target
  keeps following the entity's speed afterwards (`Follow`). A vehicle's Performance
  bounds it as esmini does: the target to its maxSpeed, and a transition whose peak
  acceleration exceeds its maxAcceleration (speeding up) or maxDeceleration (slowing
  down) stretched in time until the peak is that limit (same shape, longer span).
- LaneChangeAction: a lateral transition of the reference point to the target lane's centre
  (plus its target offset) by esmini's law (`world.actors.profiles`: the speed kept over
  ground); the target lane is an OpenDRIVE id, or lanes to the left of an entity's lane; a
  rate is the peak lateral speed.
- LaneOffsetAction: a lateral transition to an offset from the actor's lane centre (or to
  an entity's lateral position plus a value, to its left when it drives along the route:
  esmini's reading of a relative target), timed by its peak lateral acceleration
  (`LANE_OFFSET_ACCEL` when the file gives none): sinusoidal T = pi sqrt(d / 2a), cubic
  T = sqrt(6 d / a), linear and step as fast as that acceleration allows from rest to
  rest, T = 2 sqrt(d / a).
- FollowTrajectoryAction: the trajectory's shape sampled to a dense polyline
  (`avsim.scenario.openscenario.sampling`; a polyline: its resolved vertices), in route
  coordinates of the body centre; timed when the action has a time reference and the shape
  has times (time x scale + offset, plus the start time for the relative domain), else at
  the actor's speed (which a speed action may change while it runs).
- TeleportAction: the actor's body jumps to the position at once, keeping its speed.
- SpeedProfileAction: speed points, linear in time between them: each entry's speed (plus
  the referenced entity's speed at the start) its time after the previous one; an entry
  without a time, or one whose change would exceed the DynamicConstraints' acceleration
  or deceleration, takes the time that limit needs (`DISTANCE_ACCEL` where none is
  given). In follow mode a first entry at time 0 is replaced by the actor's speed.
- LateralDistanceAction: the body centre's lateral offset kept at the distance (plus half
  of both widths for freespace) left or right of the entity's reference point (the side it
  is on for `any`), renewed at every check: at once without a maxSpeed, else at that
  lateral speed.
- SynchronizeAction: the targets resolved when it starts; the actor's speed at each check
  by the speed law of `synchronize` (esmini's), until it is done.
- LongitudinalDistanceAction: keeps a distance (or a time gap at the referenced entity's
  speed) ahead of or behind the entity along its direction of travel on the route
  (`Follow`; freespace between the boxes, about their centres): without acceleration
  limits its whole error closed by the next check, at every check (esmini places the actor
  at the distance each step), else at the speed
  `GAP_GAIN` gives within the DynamicConstraints' limits (`DISTANCE_ACCEL` where one is
  missing).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from avsim.run.storyboard.snapshot import EntityState, Snapshot
from avsim.run.storyboard.synchronize import Synchronizer, SyncInput
from avsim.scenario.openscenario.model import (
    AbsoluteTargetLane,
    AbsoluteTargetLaneOffset,
    AbsoluteTargetSpeed,
    FollowTrajectoryAction,
    LaneChangeAction,
    LaneOffsetAction,
    LateralDistanceAction,
    LongitudinalDistanceAction,
    RelativeTargetSpeed,
    SpeedAction,
    SpeedProfileAction,
    SynchronizeAction,
    TeleportAction,
    TransitionDynamics,
)
from avsim.scenario.openscenario.resolve import Pose, Resolver
from avsim.scenario.openscenario.sampling import sample
from world.actors.profiles import (
    LateralCommand,
    PathCommand,
    ProfileCommand,
    Shape,
    SpeedCommand,
    TeleportCommand,
    TrackCommand,
    Transition,
    span_by_rate,
    speed_span_by_distance,
)
from world.core.rates import ACTOR_RATE
from world.hdmap import RoadMap

MOTION_STEP = 1.0 / ACTOR_RATE.hz  # [s] an actor's motion step
LANE_OFFSET_ACCEL = 0.5  # [m/s^2] a lane offset's peak lateral acceleration, if not given
GAP_GAIN = 0.5  # [1/s] a distance keeper's speed correction per metre of gap error
DISTANCE_ACCEL = 4.0  # [m/s^2] a distance keeper's limits where the file gives none
GAP_REACHED = 0.2  # [m] a non-continuous distance action ends within this of its gap ...
SPEED_MATCHED = 0.1  # [m/s] ... at the entity's speed within this


@dataclass(frozen=True, slots=True)
class Limits:
    """A vehicle's Performance: what its speed actions may ask of it."""

    max_speed: float  # [m/s] (its magnitude: files write some limits signed)
    max_accel: float  # [m/s^2] (its magnitude)
    max_decel: float  # [m/s^2] (its magnitude)

    def bound(self, speed: float) -> float:
        """[m/s] `speed` within +-max_speed."""
        top = abs(self.max_speed)
        return max(-top, min(top, speed))


@dataclass(frozen=True, slots=True)
class Follow:
    """A command the director refreshes every step from the truth: a continuous relative
    speed, or a distance to keep."""

    tag: str
    entity: str  # the one it acts on
    action: SpeedAction | LongitudinalDistanceAction | LateralDistanceAction
    after: float = 0.0  # [s] renewed from this time on (a relative speed: once its
    #   transition to the entity's speed is done)


@dataclass(frozen=True, slots=True)
class Sync:
    """A running SynchronizeAction: its targets in route coordinates (resolved when it
    starts) and its speed law's state."""

    tag: str
    entity: str
    action: SynchronizeAction
    target: tuple[float, float]  # [m] (s, offset) of the actor's target
    master_target: float  # [m] station of the master's target
    law: Synchronizer


class Commands:
    """Builds commands on one route (module doc)."""

    def __init__(self, road: RoadMap, resolver: Resolver, lane_ids: tuple[int, ...]) -> None:
        self.road = road
        self.resolver = resolver
        self.lane_ids = lane_ids

    def speed(self, tag: str, action: SpeedAction, me: EntityState, snap: Snapshot,
              limits: Limits | None = None) -> SpeedCommand:
        """A speed transition; a continuous one never reports finished. `limits`: the
        actor's Performance (a vehicle's; None: unbounded), module doc."""
        wanted = _speed_target(action, snap)
        target = wanted if limits is None else limits.bound(wanted)
        d = action.dynamics
        # a distance is converted to a time with the target asked for (esmini's order)
        span = _speed_span(d, me.speed, wanted if d.dimension == "distance" else target)
        if limits is not None:
            span = _stretched(limits, Shape(d.shape), me.speed, target, span)
        continuous = isinstance(action.target, RelativeTargetSpeed) and action.target.continuous
        return SpeedCommand(tag, Transition(me.speed, target, Shape(action.dynamics.shape),
                                            span), snap.time, continuous=continuous)

    def lane_change(self, tag: str, action: LaneChangeAction, me: EntityState,
                    snap: Snapshot, lanes: Mapping[str, int]) -> LateralCommand:
        """The reference point from its offset to the target lane's centre plus the target
        offset, by esmini's law (`world.actors.profiles`); `lanes`: the entities' lanes as
        their positions and lane changes named them (`target_route_lane`)."""
        lane = target_route_lane(action, self.lane_ids, self.road.lanes_at(me.s), snap, lanes)
        goal = float(self.road.lane(lane).offset_at(me.s)) + (action.target_lane_offset or 0.0)
        d = action.dynamics
        shape = Shape(d.shape)
        by_distance = d.dimension == "distance"
        span = d.value if d.dimension != "rate" else span_by_rate(shape, goal - me.offset,
                                                                  d.value)
        return LateralCommand(tag, Transition(me.offset, goal, shape, span), snap.time, me.s,
                              by_distance=by_distance, lane=lane, ahead=me.centre_ahead)

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
        line = sample(action.trajectory.shape, lambda p: self.resolver.resolve(p, poses),
                      Pose(me.x, me.y, me.heading))
        ahead = me.centre_ahead
        xy = [(float(x + ahead * math.cos(h)), float(y + ahead * math.sin(h)))
              for x, y, h in zip(line.x, line.y, line.heading, strict=True)]
        s, d = self.road.local_coordinates(xy)
        timing = action.time_reference
        times = None
        if timing is not None and line.times is not None:
            base = snap.time if timing.domain == "relative" else 0.0
            times = tuple(base + float(t) * timing.scale + timing.offset for t in line.times)
        return PathCommand(tag, tuple(float(x) for x in s), tuple(float(x) for x in d), times,
                           self.road.lane_at(xy[-1])[0])

    def teleport(self, tag: str, action: TeleportAction, me: EntityState,
                 snap: Snapshot) -> TeleportCommand:
        """The actor's body centre where the position puts its reference point."""
        p = self.resolver.resolve(action.position, poses_of(snap))
        ahead = me.centre_ahead
        xy = (p.x + ahead * math.cos(p.heading), p.y + ahead * math.sin(p.heading))
        s, d = self.road.local_coordinates(xy)
        lane = (self.lane_ids.index(p.lane_id) if p.lane_id in self.lane_ids
                else self.road.lane_at(xy)[0])  # a lane position's lane, as it names it
        return TeleportCommand(tag, float(s), float(d), lane)

    def speed_profile(self, tag: str, action: SpeedProfileAction, me: EntityState,
                      snap: Snapshot) -> ProfileCommand:
        """The entries as speed points (module doc)."""
        base = snap.entities[action.entity].speed if action.entity is not None else 0.0
        c = action.constraints
        accel = c.max_acceleration if c is not None and c.max_acceleration else None
        decel = c.max_deceleration if c is not None and c.max_deceleration else None
        times, speeds = [snap.time], [me.speed]
        entries = action.entries
        if action.following_mode == "follow" and entries[0].time == 0.0:
            entries = entries[1:]  # the first point is the actor's speed now
        for entry in entries:
            v = entry.speed + base
            dv = v - speeds[-1]
            limit = accel if dv > 0.0 else decel
            dt = entry.time
            if dt is None:
                dt = abs(dv) / (limit or DISTANCE_ACCEL)
            elif limit is not None and dt > 0.0 and abs(dv) / dt > limit:
                dt = abs(dv) / limit  # the constraint stretches the entry
            times.append(times[-1] + dt)
            speeds.append(v)
        return ProfileCommand(tag, tuple(times), tuple(speeds))

    def synchronize(self, tag: str, entity: str, action: SynchronizeAction,
                    snap: Snapshot, *, opening: bool = False) -> Sync:
        """The targets where the positions are when the action starts; `opening`: it
        starts at the storyboard's first check (`synchronize`)."""
        poses = poses_of(snap)
        target = self.resolver.resolve(action.target, poses)
        master = self.resolver.resolve(action.master_target, poses)
        (s, ms), (d, _) = self.road.local_coordinates([(target.x, target.y),
                                                       (master.x, master.y)])
        final = action.final_speed
        steady = final.steady_state if final is not None else None
        law = Synchronizer(action.tolerance, action.tolerance_master,
                           steady.distance if steady is not None else None,
                           steady.time if steady is not None else None, opening=opening)
        return Sync(tag, entity, action, (float(s), float(d)), float(ms), law)

    def sync_step(self, sync: Sync, snap: Snapshot, dt: float) -> tuple[TrackCommand, bool]:
        """(the actor's speed until the next check, whether the action is done);
        `dt` [s] the check period (`synchronize`)."""
        me = snap.entities[sync.entity]
        master = snap.entities[sync.action.master]
        ds = sync.master_target - master.s
        along = master.speed * math.cos(master.heading - master.route_heading)
        final = sync.action.final_speed
        vf = None
        if final is not None:
            vf = {"absolute": final.value, "delta": master.speed + final.value,
                  "factor": master.speed * final.value}[final.relative]
        speed, done = sync.law.step(SyncInput(
            dist=math.hypot(sync.target[0] - me.s, sync.target[1] - me.offset),
            master_dist=abs(ds), speed=me.speed,
            master_speed=along * math.copysign(1.0, ds), final_speed=vf), dt)
        return TrackCommand(sync.tag, max(speed, 0.0), math.inf, math.inf), done

    def keep_lateral(self, follow: Follow, me: EntityState, centre_offset: float,
                     snap: Snapshot) -> tuple[LateralCommand, bool]:
        """(the command to the lateral distance for this check, whether it is reached);
        `centre_offset`: the actor's body centre offset from the reference line [m]."""
        action = follow.action
        assert isinstance(action, LateralDistanceAction)
        ref = snap.entities[action.entity]
        want = action.distance or 0.0
        if action.freespace:
            want += 0.5 * (me.width + ref.width)
        side = {"leftToReferencedEntity": 1.0, "rightToReferencedEntity": -1.0}.get(
            action.displacement, 1.0 if me.offset >= ref.offset else -1.0)
        goal = ref.offset + side * want
        c = action.constraints
        speed = c.max_speed if c is not None and c.max_speed else None
        span = 0.0 if speed is None else abs(goal - centre_offset) / speed
        # the motion was stepped at the check's time already: its offset is one motion step
        # later's, so the renewed transition starts there
        cmd = LateralCommand(follow.tag, Transition(centre_offset, goal, Shape.LINEAR, span),
                             snap.time + MOTION_STEP, me.s)
        return cmd, abs(goal - centre_offset) < GAP_REACHED

    def place(self, tag: str, action: LongitudinalDistanceAction, me: EntityState,
              offset: float, snap: Snapshot) -> tuple[TeleportCommand, TrackCommand]:
        """An action `placed_at_once`: the actor's centre where the distance (or the time gap
        at the entity's speed) puts it ahead of or behind the referenced entity along the
        entity's way - between the reference points, or bumper to bumper for `freespace` -
        at its lateral `offset` [m], and its speed the entity's (esmini places it so and
        ends the action)."""
        ref = snap.entities[action.entity]
        want = action.distance if action.distance is not None else (
            (action.time_gap or 0.0) * max(ref.speed, 0.0))
        way = (-1.0 if action.displacement == "trailingReferencedEntity" else 1.0) \
            * _travel(ref)
        if action.freespace:
            centre = ref.s + _travel(ref) * ref.centre_ahead \
                + way * (want + 0.5 * (me.length + ref.length))
        else:
            centre = ref.s + way * want + _travel(me) * me.centre_ahead
        return (TeleportCommand(tag, centre, offset, None),
                TrackCommand(tag, max(0.0, ref.speed), math.inf, math.inf))

    def follow(self, follow: Follow, me: EntityState, snap: Snapshot, max_speed: float,
               period: float) -> tuple[TrackCommand, bool]:
        """(the command for this step, whether the follow's goal is reached); `period` [s]
        until the next check (module doc: a distance without acceleration limits is
        reached within it)."""
        action = follow.action
        assert not isinstance(action, LateralDistanceAction)
        if isinstance(action, SpeedAction):
            target = _speed_target(action, snap)
            return TrackCommand(follow.tag, target, DISTANCE_ACCEL, DISTANCE_ACCEL,
                                max_speed), False
        ref = snap.entities[action.entity]
        want = action.distance if action.distance is not None else (
            (action.time_gap or 0.0) * max(ref.speed, 0.0))
        sign = -1.0 if action.displacement == "trailingReferencedEntity" else 1.0
        gap = sign * _travel(ref) * (me.s - ref.s)  # ahead of it along its way (trailing: behind)
        if action.freespace:  # bumper to bumper: between the boxes, about their centres
            centres = (me.s + _travel(me) * me.centre_ahead) - (ref.s + _travel(ref)
                                                                 * ref.centre_ahead)
            gap = sign * _travel(ref) * centres - 0.5 * (me.length + ref.length)
        c = action.constraints
        if c is None or not (c.max_acceleration or c.max_deceleration):
            # the whole gap error closed within the period at every check, as esmini moves
            # the actor onto the distance at every step; it ends such an action once the
            # actor is within GAP_REACHED of its distance
            target = max(0.0, ref.speed - sign * (gap - want) / period)
            return (TrackCommand(follow.tag, target, math.inf, math.inf),
                    abs(gap - want) < GAP_REACHED)
        reached = abs(gap - want) < GAP_REACHED and abs(me.speed - ref.speed) < SPEED_MATCHED
        target = max(0.0, ref.speed + GAP_GAIN * sign * (gap - want))
        accel = c.max_acceleration or DISTANCE_ACCEL
        decel = c.max_deceleration or DISTANCE_ACCEL
        top = c.max_speed if c.max_speed else max_speed
        return TrackCommand(follow.tag, min(target, top), accel, decel, top), reached


def placed_at_once(action: LongitudinalDistanceAction) -> bool:
    """Whether a distance action puts its actor at the distance at once and ends
    (`Commands.place`): it does not go on (`continuous` false) and has no acceleration
    limits, as NCAP files use it to set a gap right after Init."""
    c = action.constraints
    return not action.continuous and (c is None or not (c.max_acceleration
                                                        or c.max_deceleration))


def _travel(entity: EntityState) -> float:
    """+1 if `entity` heads along the route, -1 against it."""
    return 1.0 if math.cos(entity.heading - entity.route_heading) >= 0.0 else -1.0


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
    if d.value == 0.0:
        raise ValueError(f"a speed change at rate {d.value:g} m/s^2 never ends")
    return span_by_rate(shape, target - start, abs(d.value))  # the sign is the change's
    #   (ASAM's 1.2 examples write a braking rate negative; esmini plays its magnitude)


def _stretched(limits: Limits, shape: Shape, start: float, target: float,
               span: float) -> float:
    """[s] a speed transition's span stretched so that the peak acceleration of its shape
    is at most the vehicle's maxAcceleration when speeding up, its maxDeceleration when
    slowing down (a step, or a span of 0, changes at once: unbounded, as esmini's)."""
    if span <= 0.0 or shape is Shape.STEP:
        return span
    limit = abs(limits.max_accel if target > start else limits.max_decel)
    if limit == 0.0:
        return math.inf  # a vehicle that cannot change its speed keeps it
    return max(span, span_by_rate(shape, target - start, limit))


def _offset_span(shape: Shape, distance: float, accel: float) -> float:
    """[s] a lateral move of `distance` [m] at a peak lateral acceleration `accel` [m/s^2]."""
    if distance == 0.0:
        return 0.0
    if shape is Shape.SINUSOIDAL:
        return math.pi * math.sqrt(distance / (2.0 * accel))
    if shape is Shape.CUBIC:
        return math.sqrt(6.0 * distance / accel)
    return 2.0 * math.sqrt(distance / accel)


def target_route_lane(action: LaneChangeAction, lane_ids: tuple[int, ...], lanes_here: int,
                      snap: Snapshot, lanes: Mapping[str, int] | None = None) -> int:
    """The route lane (0 = rightmost) a lane change goes to: an OpenDRIVE lane id of the
    route, or lanes to the left of an entity's lane: its lane in `lanes` (as its position
    or its last lane change named it: esmini keeps a lane position's lane even where the
    offset puts the entity over the border), else the lane its reference point is in.
    `lanes_here`: the route's lane count at the actor; `ValueError` for a lane the route
    does not have there."""
    target = action.target
    if isinstance(target, AbsoluteTargetLane):
        lane_id = int(target.value)
        if lane_id not in lane_ids:
            raise ValueError(f"lane {lane_id} is not a lane of the route")
        lane = lane_ids.index(lane_id)
    else:
        ref_lane = (lanes or {}).get(target.entity, snap.entities[target.entity].lane)
        if ref_lane is None:
            raise ValueError(f"entity {target.entity} is in no lane")
        lane = ref_lane + target.value
    if not 0 <= lane < lanes_here:
        raise ValueError(f"the target lane (route lane {lane}) does not exist here")
    return lane
