"""Scripted NPC behaviour in route coordinates: triggers fire actions, motion is integrated.

Pure (no PyBullet): `NpcMotion` holds one actor's state along the route (station, lateral
offset from the reference line, speed, lateral speed) and its pending actions; `step()`
advances it by dt. Scripted motion is smooth: the speed changes at the action's
acceleration, and lateral moves follow a trapezoidal lateral-speed profile (ramps of
`LATERAL_ACCEL`, cruise at the action's lateral speed), so positions and headings never
jump. A town driver's `cap` (`world.actors.town_traffic`) may lower the speed at once; the
speed comes back up at `CAP_ACCEL` when it lifts.

Actions (scenario format): `speed` (to a speed at an acceleration), `lane_change` (to a
lane's centre at a lateral speed), `walk` (across the road to an offset from the actor's
lane centre, at a walking speed: the same trapezoidal lateral move), `stop` (brake to rest).
Triggers: `time`, `ego_s`, `gap` (bumper-to-bumper distance to the ego along the route),
`after` (an earlier action ended, plus a delay). Each action fires once, when its trigger
first holds; it ends when it reaches its target, or when a later action of the same kind
(longitudinal: speed, stop; lateral: lane change, walk) replaces it.

Headings: a vehicle's body points along its velocity while it moves faster than 0.1 m/s
(along its lane at rest). A pedestrian faces where it walks, also straight across the road
(no longitudinal speed), turning towards it at `PEDESTRIAN_TURN_RATE`, and keeps the last
heading it walked in while it stands. Once a director's path ends, an actor goes on along
its lane at the path's last speed over ground (a pedestrian keeping its heading, until its
next command), as esmini moves an entity on along the road after its trajectory.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from world.actors.profiles import (
    LateralCommand,
    PathCommand,
    ProfileCommand,
    SpeedCommand,
    TeleportCommand,
    TrackCommand,
    lane_change_step,
)
from world.frames import wrap_angle
from world.spec import (
    ActionSpec,
    AfterTrigger,
    EgoStationTrigger,
    GapTrigger,
    LaneChangeAction,
    SpeedAction,
    StopAction,
    TimeTrigger,
    Trigger,
    WalkAction,
)

LATERAL_ACCEL = 1.5  # [m/s^2] ramp of the lateral speed at the start and end of a lane change
ARRIVED = 1e-3  # [m] lateral distance that counts as arrived
PEDESTRIAN_TURN_RATE = math.pi  # [rad/s] a pedestrian turns to face where it walks (90 deg: 0.5 s)
PEDESTRIAN_MOVING = 0.05  # [m/s] a pedestrian slower than this over ground keeps its heading
ALONG_EPS = 1e-9  # [m/s] a path's last segment slower than this along the route runs across it
CAP_ACCEL = 1.5  # [m/s^2] a capped NPC (a town driver) speeds up again at this

SpeedLike = SpeedCommand | TrackCommand | ProfileCommand
Command = SpeedLike | LateralCommand | PathCommand | TeleportCommand
LaneOffset = Callable[[int, float], float]
"""(lane index, station) -> lateral offset [m] of that lane's centre from the reference line."""


@dataclass(frozen=True, slots=True)
class TriggerContext:
    """What triggers are judged on, at one step."""

    t: float  # [s] sim time
    ego_s: float  # [m] the ego's centre station
    gap: float  # [m] bumper-to-bumper distance between this actor and the ego along the route


def trigger_holds(
    trigger: Trigger, ctx: TriggerContext, ended_at: Sequence[float | None]
) -> bool:
    """Whether `trigger` holds now. `ended_at[i]` [s] is when item i of the same list (an
    actor's actions, or the ego's events) ended, None while it has not; `after` reads it.
    Shared by the NPC actions and the ego events (`world.ego.events`)."""
    if isinstance(trigger, TimeTrigger):
        return ctx.t >= trigger.time
    if isinstance(trigger, EgoStationTrigger):
        return ctx.ego_s >= trigger.s
    if isinstance(trigger, GapTrigger):
        return ctx.gap <= trigger.gap
    if isinstance(trigger, AfterTrigger):
        ended = ended_at[trigger.index]
        return ended is not None and ctx.t >= ended + trigger.delay
    raise TypeError(f"unknown trigger {trigger!r}")


class NpcMotion:
    """One actor's kinematic state in route coordinates and its scripted actions."""

    def __init__(
        self, s: float, offset: float, speed: float, direction: int,
        actions: tuple[ActionSpec, ...], *, lane: int = 0, pedestrian: bool = False,
        facing: float = 0.0,
    ) -> None:
        """`lane`: the lane whose centre `walk` offsets are measured from (a `lane_change`
        moves it); `pedestrian`: face the walking direction (module doc), from `facing`
        [rad] (its heading from its lane's direction of travel, left positive) at the
        start."""
        self.s = s  # [m] station of the actor's centre
        self.offset = offset  # [m] lateral offset of its centre from the reference line, left +
        self.speed = speed  # [m/s] along its lane's direction of travel
        self.lateral_speed = 0.0  # [m/s] d(offset)/dt
        self.direction = direction  # +1 with the route, -1 against
        self.lane = lane  # the lane `walk` offsets are measured from
        self.pedestrian = pedestrian  # faces where it walks
        self._facing = facing if pedestrian else 0.0  # [rad] a pedestrian's heading
        #   relative to its lane's direction
        self.actions = actions
        self.fired_at: list[float | None] = [None] * len(actions)  # [s]
        self.ended_at: list[float | None] = [None] * len(actions)  # [s]
        self._target_speed = speed  # [m/s]
        self._planned = speed  # [m/s] the scripted speed (actions alone)
        self.cap: float | None = None  # [m/s] a town driver's limit (`world.actors.town_traffic`)
        self._accel = 0.0  # [m/s^2] magnitude towards the target speed
        self._speed_action: int | None = None  # index of the running longitudinal action
        self._target_offset = offset  # [m]
        self._lateral_max = 0.0  # [m/s] cruise lateral speed of the running lateral move
        self._lateral_action: int | None = None  # index of the running lateral action
        # a director's commands (`world.actors.profiles`), over the actions above while set
        self._speed_cmd: SpeedLike | None = None
        self._lateral_cmd: LateralCommand | None = None
        self._path_cmd: PathCommand | None = None
        self._path_index = 0  # the vertex an untimed path heads for
        self._path_speed = 0.0  # [m/s] the speed an untimed path is followed at
        self._keep_facing = False  # a pedestrian moving on after a path keeps its heading
        # a lane change by esmini's law (`world.actors.profiles`): its progress, its
        #   reference point (station [m], offset [m]), the body's heading from the route's
        #   direction [rad] (left +) and where the step puts the body centre
        self._lc_x = 0.0  # [s] or [m]
        self._speed_before = speed  # [m/s] at the start of the step (a lane change's)
        self._ref: tuple[float, float] | None = None
        self._yaw: float | None = None
        self._place: tuple[float, float] | None = None
        self.finished: list[str] = []  # tags of commands that reached their goal, in order
        self.jumped = False  # teleported since its body was last placed

    # -- triggers --------------------------------------------------------------------------

    def fire_due(self, ctx: TriggerContext, lane_offset: LaneOffset) -> list[int]:
        """Start every action whose trigger holds now; returns their indices."""
        started = []
        for i, spec in enumerate(self.actions):
            if self.fired_at[i] is None and trigger_holds(spec.trigger, ctx, self.ended_at):
                self.fired_at[i] = ctx.t
                self._start(i, spec, lane_offset)
                started.append(i)
        return started

    def _start(self, i: int, spec: ActionSpec, lane_offset: LaneOffset) -> None:
        action = spec.action
        if isinstance(action, SpeedAction):
            self._target_speed, self._accel, self._speed_action = action.speed, action.accel, i
        elif isinstance(action, StopAction):
            self._target_speed, self._accel, self._speed_action = 0.0, action.decel, i
        elif isinstance(action, LaneChangeAction):
            self._target_offset = lane_offset(action.to_lane, self.s)
            self._lateral_max, self._lateral_action = action.lateral_speed, i
            self.lane = action.to_lane
        elif isinstance(action, WalkAction):
            self._target_offset = lane_offset(self.lane, self.s) + action.to_offset
            self._lateral_max, self._lateral_action = action.speed, i
        # an action replacing a running one of the same kind ends the old one now
        for j in range(len(self.actions)):
            running = self.fired_at[j] is not None and self.ended_at[j] is None
            if j != i and running and _same_kind(self.actions[j].action, action):
                self.ended_at[j] = self.fired_at[i]

    # -- a director's commands ---------------------------------------------------------------

    def command(self, cmd: Command) -> None:
        """Drive by `cmd` from now on: a speed, track or profile command takes the speed (on
        an untimed path, the speed it is followed at), a lateral command the offset, a path
        both (each replaces what drove that part before); a teleport moves the actor at
        once and is done."""
        self._keep_facing = False
        if not isinstance(cmd, SpeedLike):
            self._ref = self._yaw = None
        if isinstance(cmd, TeleportCommand):
            self.s, self.offset, self._target_offset = cmd.s, cmd.offset, cmd.offset
            self._path_cmd = self._lateral_cmd = None
            self.lateral_speed = 0.0
            if cmd.lane is not None:
                self.lane = cmd.lane
            self.jumped = True
            self.finished.append(cmd.tag)
        elif isinstance(cmd, PathCommand):
            self._speed_cmd = self._lateral_cmd = None
            self._path_cmd, self._path_index = cmd, 0
            self._path_speed = self.ground_speed
        elif isinstance(cmd, LateralCommand):
            self._path_cmd, self._lateral_cmd = None, cmd
            self._start_reference(cmd)
        elif self._path_cmd is not None and self._path_cmd.times is None:
            self._speed_cmd = cmd
        else:
            self._path_cmd, self._speed_cmd = None, cmd

    def cancel(self, tag: str) -> None:
        """Stop the command tagged `tag` (if it still runs): the actor holds its speed and
        offset from here on."""
        if self._speed_cmd is not None and self._speed_cmd.tag == tag:
            self._speed_cmd = None
            self._hold_speed()
        if self._lateral_cmd is not None and self._lateral_cmd.tag == tag:
            self._lateral_cmd = None
            self._ref = self._yaw = None
        if self._path_cmd is not None and self._path_cmd.tag == tag:
            self._path_cmd = None
            self._hold_speed()
            self.lateral_speed = 0.0

    def _start_reference(self, cmd: LateralCommand) -> None:
        """A lane change by esmini's law starts from the reference point `cmd.ahead` behind
        the body centre along its heading, the body aligned with its lane (esmini resets
        the heading when a lane change starts)."""
        if cmd.ahead is None:
            return
        yaw = self.heading_offset * self.direction  # from the route's direction, left +
        self._ref = (self.s - self.direction * cmd.ahead * math.cos(yaw),
                     self.offset - cmd.ahead * math.sin(yaw))
        self._lc_x, self._yaw = 0.0, 0.0

    def _hold_speed(self) -> None:
        self._planned = self._target_speed = self.speed
        self._speed_action = None

    def _step_commands(self, t: float, dt: float, curvature: float) -> bool:
        """Step the director's commands; False if none drives the actor."""
        if self._path_cmd is not None:
            cmd = self._path_cmd
            if self._speed_cmd is not None:  # the speed an untimed path is followed at
                self.speed = self._path_speed
                self._step_speed_cmd(t, dt)
                self._path_speed = self.speed
            along, across, done, self._path_index = cmd.velocity(
                t, self.s, self.offset, self._path_speed, dt, self._path_index)
            self.speed, self.lateral_speed = along * self.direction, across
            if done:  # then on along the route at its last segment's speed along it
                self._path_cmd = None
                self._planned = self._target_speed = self._speed_after(cmd)
                self._keep_facing = self.pedestrian
                self._speed_action = None
                if cmd.lane is not None:
                    self.lane = cmd.lane
                self.finished.append(cmd.tag)
            return True
        if self._speed_cmd is None and self._lateral_cmd is None:
            return False
        self._speed_before = self.speed
        if self._speed_cmd is None:
            self._step_speed(t, dt)
        else:
            self._step_speed_cmd(t, dt)
        if self._lateral_cmd is None:
            self._step_lateral(t, dt)
        else:
            self._step_lateral_cmd(t, dt, curvature)
        return True

    def _speed_after(self, cmd: PathCommand) -> float:
        """[m/s] the speed along its lane an actor goes on at once `cmd` ends: its last
        segment's speed over ground, forwards unless that segment led back along the route
        (or, straight across the road, a pedestrian faces backwards)."""
        along, ground = cmd.speeds_at_end(self._path_speed)
        if abs(along) > ALONG_EPS:
            return math.copysign(ground, along) * self.direction
        return -ground if math.cos(self._facing) < 0.0 else ground

    def _step_speed_cmd(self, t: float, dt: float) -> None:
        cmd = self._speed_cmd
        if isinstance(cmd, TrackCommand):
            change = cmd.target - self.speed
            change = max(-cmd.max_decel * dt, min(cmd.max_accel * dt, change))
            self.speed = min(cmd.max_speed, max(0.0, self.speed + change))
            self._hold_speed()
            return
        if isinstance(cmd, ProfileCommand):
            self.speed, done = cmd.at(t + dt)
            self._hold_speed()
            if done:
                self._speed_cmd = None
                self.finished.append(cmd.tag)
            return
        assert cmd is not None
        self.speed, _, done = cmd.transition.at(t + dt - cmd.t0)
        self._hold_speed()
        if done and not cmd.continuous:
            self._speed_cmd = None
            self.finished.append(cmd.tag)

    def _step_lateral_cmd(self, t: float, dt: float, curvature: float) -> None:
        cmd = self._lateral_cmd
        assert cmd is not None
        if cmd.ahead is not None:
            self._step_lane_change(cmd, cmd.ahead, dt, curvature)
            return
        if cmd.by_distance:
            scale = max(1.0 - curvature * self.offset, 1e-3)
            x = abs(self.s + self.direction * self.speed * dt / scale - cmd.s0)
        else:
            x = t + dt - cmd.t0
        offset, _, done = cmd.transition.at(x)
        self.lateral_speed = (offset - self.offset) / dt
        if done:
            self._lateral_cmd = None
            self._target_offset = offset
            if cmd.lane is not None:
                self.lane = cmd.lane
            self.finished.append(cmd.tag)

    def _step_lane_change(self, cmd: LateralCommand, ahead: float, dt: float,
                          curvature: float) -> None:
        """One step of esmini's lane change law: the reference point moves, the body centre
        `ahead` [m] in front of it along the step's heading (0 once done)."""
        assert self._ref is not None
        step = lane_change_step(cmd.transition, self._lc_x, cmd.by_distance, self._speed_before, dt)
        self._lc_x = step.x
        scale = max(1.0 - curvature * step.offset, 1e-3)  # station rate at that offset
        s_ref = self._ref[0] + self.direction * step.along / scale
        self._ref = (s_ref, step.offset)
        yaw = 0.0 if step.done else step.heading
        centre = (s_ref + self.direction * ahead * math.cos(yaw) / scale,
                  step.offset + ahead * math.sin(yaw))
        self.lateral_speed = (centre[1] - self.offset) / dt
        self._place, self._yaw = centre, yaw
        if step.done:
            self._lateral_cmd = None
            self._ref = self._yaw = None
            self._target_offset = centre[1]
            if cmd.lane is not None:
                self.lane = cmd.lane
            self.finished.append(cmd.tag)

    # -- motion ------------------------------------------------------------------------------

    def step(self, t: float, dt: float, curvature: float) -> None:
        """Advance by dt [s]. `curvature` [1/m] is the reference line's at the actor's station
        (the station rate of a body at lateral offset r is v / (1 - k r))."""
        if not self._step_commands(t, dt, curvature):
            self._step_speed(t, dt)
            self._step_lateral(t, dt)
        if self.pedestrian:
            self._turn(dt)
        if self._place is not None:  # a lane change by esmini's law placed the body
            (self.s, self.offset), self._place = self._place, None
            return
        scale = 1.0 - curvature * self.offset
        self.s += self.direction * self.speed * dt / max(scale, 1e-3)
        self.offset += self.lateral_speed * dt

    def _turn(self, dt: float) -> None:
        """A pedestrian turns towards its direction of travel, at most at the turn rate."""
        if self._keep_facing or math.hypot(self.speed, self.lateral_speed) < PEDESTRIAN_MOVING:
            return
        course = math.atan2(self.lateral_speed, self.direction * self.speed)  # route frame
        wanted = course if self.direction > 0 else course - math.pi  # from its lane's direction
        error = wrap_angle(wanted - self._facing)
        limit = PEDESTRIAN_TURN_RATE * dt
        self._facing = wrap_angle(self._facing + max(-limit, min(limit, error)))

    def _step_speed(self, t: float, dt: float) -> None:
        """The scripted speed one step towards its target at the action's acceleration
        (the action ends on it), then the cap."""
        error = self._target_speed - self._planned
        change = self._accel * dt
        if abs(error) <= change:
            self._planned = self._target_speed
            if self._speed_action is not None:
                self.ended_at[self._speed_action] = t
                self._speed_action = None
        else:
            self._planned += math.copysign(change, error)
        if self.cap is None:
            self.speed = self._planned
        else:  # a town driver's rules: never above the cap, back up at CAP_ACCEL
            self.speed = max(0.0, min(self._planned, self.cap, self.speed + CAP_ACCEL * dt))

    def _step_lateral(self, t: float, dt: float) -> None:
        """The lateral speed one step along the trapezoidal profile to the target offset
        (the action ends on arrival, within `ARRIVED`)."""
        if self._lateral_action is None:
            self.lateral_speed = 0.0
            return
        remaining = self._target_offset - self.offset
        if abs(remaining) < ARRIVED and abs(self.lateral_speed) <= LATERAL_ACCEL * dt:
            self.lateral_speed = 0.0
            self.ended_at[self._lateral_action] = t
            self._lateral_action = None
            return
        # trapezoidal profile in discrete time: the fastest lateral speed k * a dt from which
        # slowing by a dt per step (k + (k-1) + ... + 1 steps of a dt^2) still stops on the
        # target, capped at the action's lateral speed
        step = LATERAL_ACCEL * dt  # [m/s] speed change per step
        k = math.floor((math.sqrt(1.0 + 8.0 * abs(remaining) / (step * dt)) - 1.0) / 2.0)
        if k == 0:  # closer than one step at the slowest speed: land on the target
            self.lateral_speed = remaining / dt
            return
        wanted = math.copysign(min(self._lateral_max, k * step), remaining)
        self.lateral_speed += max(-step, min(step, wanted - self.lateral_speed))

    @property
    def heading_offset(self) -> float:
        """[rad] the body's yaw relative to its lane's direction of travel (module doc)."""
        if self.pedestrian:
            return self._facing
        if self._yaw is not None:  # a lane change by esmini's law
            return self._yaw * self.direction
        if self.speed <= 0.1:
            return 0.0
        return math.atan2(self.lateral_speed, self.speed) * self.direction

    @property
    def ground_speed(self) -> float:
        """[m/s] speed over ground, the lateral motion included."""
        return math.hypot(self.speed, self.lateral_speed)


def _same_kind(a: object, b: object) -> bool:
    """Whether actions a and b are both longitudinal or both lateral."""
    longitudinal = (SpeedAction, StopAction)
    lateral = (LaneChangeAction, WalkAction)
    return (isinstance(a, longitudinal) and isinstance(b, longitudinal)) or (
        isinstance(a, lateral) and isinstance(b, lateral)
    )
