"""The director: plays an OpenSCENARIO storyboard on a world, step by step.

At each trigger check (`world.core.rates.TRIGGER_RATE`) it takes the truth's snapshot
(`truth.TruthTracker`), steps the storyboard (`runtime.StoryRuntime`: which actions start
and stop now), then reports the actions whose commands reached their goal since the last
check (they end now, after this check's triggers: a condition on their end sees it at the
next check, as esmini evaluates the triggers of a step before it steps the actions), and
turns each started action into a command on each of its actors' motions (`commands`); a
distance action that places its actor at once ends in the check it starts (esmini's). Commands the
truth must steer every step (a distance to keep, a continuous relative speed) are renewed
at each check. Actions on the car under test are its controller's (activation,
assignment): they complete at once and set the switch of its automated driving function
(`World.engaged`, `engages`): on, the stack drives it; off (before a storyboard activates
its controller: `avsim.scenario.openscenario.convert`), the driver holds its Init speed.
Its speed and lane changes and pedal overrides are its driver's inputs (`driver`).
A scripted car under test (`World.scripted`, `world.ego.scripted`) takes every other action
as an actor does, on its own motion; its controller actions then change nothing. Entity
actions (add, delete, visibility, lights) are played at once (`entity_player`).
The environment an EnvironmentAction sets (in the runtime's story state) is handed to the
world at the check it starts (`avsim.run.environment`): light, fog and precipitation for the
sensors, the road's friction for the physics.
"""

from __future__ import annotations

from collections.abc import Iterable

from avsim.run.environment import scene_environment
from avsim.run.storyboard.commands import (
    Commands,
    Follow,
    Limits,
    Sync,
    placed_at_once,
    poses_of,
)
from avsim.run.storyboard.conditions import Resolved
from avsim.run.storyboard.driver import Driver
from avsim.run.storyboard.entity_player import ENTITY_ACTIONS, EntityPlayer
from avsim.run.storyboard.runtime import StartedAction, StoryRuntime
from avsim.run.storyboard.snapshot import EntityState, Snapshot
from avsim.run.storyboard.truth import TruthTracker
from avsim.scenario.openscenario.actions import engages
from avsim.scenario.openscenario.environment import Environment
from avsim.scenario.openscenario.model import (
    ActivateControllerAction,
    AssignControllerAction,
    FollowTrajectoryAction,
    LaneChangeAction,
    LaneOffsetAction,
    LateralDistanceAction,
    LongitudinalDistanceAction,
    OverrideControllerValueAction,
    Position,
    PrivateAction,
    SpeedAction,
    SpeedProfileAction,
    SynchronizeAction,
    TeleportAction,
    Vehicle,
)
from avsim.scenario.openscenario.program import StoryProgram
from avsim.scenario.openscenario.resolve import Resolver
from world.actors.behaviour import Command, NpcMotion
from world.actors.profiles import LateralCommand, TrackCommand
from world.core.rates import TRIGGER_RATE
from world.world import World

CONTROLLER_ACTIONS = (ActivateControllerAction, AssignControllerAction)
WALKING_TOP = 3.0  # [m/s] a pedestrian's or object's top speed when it keeps a distance
INIT = "Init"  # the action id prefix of the Init actions the director starts itself
CHECK_PERIOD = 1.0 / TRIGGER_RATE.hz  # [s] between two trigger checks


class DirectorError(RuntimeError):
    """An action that cannot be played (a lane that does not exist, ...)."""


class Director:
    """One storyboard on one world (module doc)."""

    def __init__(self, program: StoryProgram, world: World) -> None:
        self.program = program
        self.world = world
        self.truth = TruthTracker(program, world)
        self.resolver = Resolver(program.chain)
        osc = program.scenario
        self.runtime = StoryRuntime(osc.storyboard, osc.parameters, self._resolve,
                                    osc.variables, self._lanes)
        self.commands = Commands(world.road, self.resolver, program.lane_ids)
        self._index = dict(program.actors)
        self._pending: dict[str, set[str]] = {}  # action id -> tags still running
        self._follows: dict[str, Follow] = {}  # tag -> a command renewed every check
        self._syncs: dict[str, Sync] = {}  # tag -> a synchronization renewed every check
        self._tag_action: dict[str, str] = {}  # tag -> action id
        self.ended = False
        self.ended_at: float | None = None  # [s] when the StopTrigger fired
        self._first = True
        self._opening = False  # this check is the storyboard's first
        self._top = {e.name: getattr(e.object, "max_speed", WALKING_TOP)
                     for e in osc.entities}  # [m/s] each entity's top speed
        self._limits = {e.name: Limits(e.object.max_speed, e.object.max_accel,
                                       e.object.max_decel)
                        for e in osc.entities if isinstance(e.object, Vehicle)}
        self.driver = Driver(world, program.ego, program.lane_ids)  # the stack's car's
        self.entities = EntityPlayer(program, world, self.commands,
                                     self.runtime.story_state)  # add, delete, looks
        self._environment: Environment | None = None  # the one last handed to the world

    def _resolve(self, position: Position, snap: Snapshot) -> Resolved:
        """Where a condition's position is now: map (x, y), route (s, offset)."""
        p = self.resolver.resolve(position, poses_of(snap))
        s, d = self.world.road.local_coordinates((p.x, p.y))
        return p.x, p.y, float(s), float(d)

    def _lanes(self, s: float) -> tuple[int, int]:
        """(lanes of the route's direction, oncoming lanes) at station s [m]."""
        c = self.world.road.cross_section_at(s)
        return c.lanes, c.oncoming_lanes

    # -- stepping -------------------------------------------------------------------------------

    def step(self) -> bool:
        """One trigger check; True once the storyboard's StopTrigger has fired."""
        snap = self.truth.snapshot()
        self._opening = self._first
        if self._first:
            self._first = False
            for i, item in enumerate(self.program.init_commands):
                started = StartedAction(f"{INIT}#{i}", f"init {item.entity}",
                                        (item.entity,), item.action)
                self._start(started, snap)
        result = self.runtime.step(snap)
        self._hand_over_environment(snap.time)
        for action_id in result.stopped:
            self._stop(action_id)
        self._collect_finished(snap)
        for started in result.started:
            self._start(started, snap)
        self._renew(snap)
        if result.ended and not self.ended:
            self.ended, self.ended_at = True, snap.time
        return self.ended

    def _hand_over_environment(self, t: float) -> None:
        """The world takes the environment in effect when an EnvironmentAction set a new one
        (before or at this check, time `t` [s])."""
        state = self.runtime.story_state
        env = state.environment
        if env is None or env is self._environment:
            return
        self._environment = env
        self.world.set_environment(scene_environment(env, self.world.environment,
                                                     state.time_of_day(t)))

    def _motion(self, entity: str) -> NpcMotion | None:
        """The motion that plays `entity`'s actions: an actor's, or the scripted car under
        test's; None for the car the stack drives."""
        scripted = self.world.scripted
        if entity == self.program.ego and scripted is not None:
            return scripted.motion
        i = self._index.get(entity)
        return None if i is None else self.world.actors.motions[i]

    def _entity_lanes(self) -> dict[str, int]:
        """Each commanded entity's route lane as its position or lane change named it."""
        lanes = {name: self.world.actors.motions[i].lane for name, i in self._index.items()}
        scripted = self.world.scripted
        if scripted is not None:
            lanes[self.program.ego] = scripted.motion.lane
        return lanes

    def _motions(self) -> list[NpcMotion]:
        """Every motion the director commands."""
        scripted = self.world.scripted
        return [*self.world.actors.motions, *([scripted.motion] if scripted else [])]

    def _collect_finished(self, snap: Snapshot) -> None:
        """The commands that reached their goal since the last check end their actions."""
        for motion in self._motions():
            done, motion.finished = motion.finished, []
            self._finish(done, snap.time)
        lane_done = self.driver.check(snap, CHECK_PERIOD)
        if lane_done is not None:
            self._finish([lane_done], snap.time)

    def _finish(self, tags: Iterable[str], t: float) -> None:
        for tag in tags:
            action_id = self._tag_action.pop(tag, None)
            if action_id is None:
                continue
            pending = self._pending.get(action_id)
            if pending is None:
                continue
            pending.discard(tag)
            if not pending:
                del self._pending[action_id]
                if not action_id.startswith(INIT):
                    self.runtime.action_done(action_id, t)

    def _stop(self, action_id: str) -> None:
        for tag in self._pending.pop(action_id, set()):
            self._tag_action.pop(tag, None)
            self._follows.pop(tag, None)
            self._syncs.pop(tag, None)
            entity = tag.rpartition("@")[2]
            motion = self._motion(entity)
            if motion is not None:
                motion.cancel(tag)
            else:
                self.driver.release_lane(tag)

    def _start(self, started: StartedAction, snap: Snapshot) -> None:
        action = started.action
        if isinstance(action, (*CONTROLLER_ACTIONS, OverrideControllerValueAction)):
            self._control(started)  # the runtime completes these itself
            return
        if isinstance(action, ENTITY_ACTIONS):  # so are these (`entity_player`)
            for entity in started.entities:
                self.entities.play(f"{started.action_id}@{entity}", entity, action, snap)
            return
        tags = self._start_on_entities(started, action, snap)
        if tags:
            self._pending[started.action_id] = tags
            if isinstance(action, LongitudinalDistanceAction) and placed_at_once(action):
                # esmini places the actor and ends the action in the step it starts: an
                # element waiting on its end sees it at the next check
                self._finish(sorted(tags), snap.time)
        elif not started.action_id.startswith(INIT):
            self.runtime.action_done(started.action_id, snap.time)

    def _start_on_entities(self, started: StartedAction, action: PrivateAction,
                           snap: Snapshot) -> set[str]:
        """Start the motion `action` of `started` on each of its entities (an actor's
        motion, or the driver of the car the stack drives); the tags of those it runs on."""
        tags = set()
        for entity in started.entities:
            tag = f"{started.action_id}@{entity}"
            motion = self._motion(entity)
            if motion is None and entity != self.program.ego:
                raise DirectorError(f"{started.name}: {entity} has no motion")
            if motion is None and not self._drive(tag, action, snap):
                continue  # done as given
            tags.add(tag)
            self._tag_action[tag] = started.action_id
            if motion is not None:
                self._command(tag, entity, motion, action, snap)
        return tags

    def _control(self, started: StartedAction) -> None:
        """A controller action on the car under test: its function's switch, or its
        driver's pedals (`driver`); on a scripted one they change nothing."""
        action = started.action
        if self.program.ego not in started.entities or self.world.scripted is not None:
            return
        if isinstance(action, OverrideControllerValueAction):
            self.driver.override(action)
            return
        assert isinstance(action, CONTROLLER_ACTIONS)
        if engages(action, False):
            self.driver.switched_on()
        self.world.engaged = engages(action, self.world.engaged)

    def _drive(self, tag: str, action: PrivateAction, snap: Snapshot) -> bool:
        """An action on the car the stack drives, as its driver's input (`driver`): True
        while it runs (a lane change until the car is in the target lane), False when it
        is done as given (a set speed)."""
        try:
            if isinstance(action, SpeedAction):
                self.driver.set_speed(action, snap)
                return False
            if isinstance(action, LaneChangeAction):
                self.driver.lane_change(tag, action, snap)
                return True
        except ValueError as e:
            raise DirectorError(f"{tag}: {e}") from None
        raise DirectorError(f"{tag}: {type(action).__name__} on the car under test: not "
                            "supported (avsim's stack drives it)")

    def _command(self, tag: str, entity: str, motion: NpcMotion, action: PrivateAction,
                 snap: Snapshot) -> None:
        me = snap.entities[entity]
        try:
            if isinstance(action, SpeedAction):
                cmd = self.commands.speed(tag, action, me, snap, self._limits.get(entity))
                motion.command(cmd)
                if cmd.continuous:
                    self._follows[tag] = Follow(tag, entity, action,
                                                after=snap.time + cmd.transition.span)
            elif isinstance(action, LongitudinalDistanceAction) and placed_at_once(action):
                for placed in self.commands.place(tag, action, me, motion.offset, snap):
                    motion.command(placed)  # the teleport ends the action
            elif isinstance(action, LongitudinalDistanceAction | LateralDistanceAction):
                self._follows[tag] = Follow(tag, entity, action)
            elif isinstance(action, SynchronizeAction):
                self._syncs[tag] = self.commands.synchronize(tag, entity, action, snap,
                                                             opening=self._opening)
            else:
                motion.command(self._once(tag, action, me, motion, snap))
        except ValueError as e:
            raise DirectorError(f"{tag}: {e}") from None

    def _once(self, tag: str, action: PrivateAction, me: EntityState, motion: NpcMotion,
              snap: Snapshot) -> Command:
        """The command of an action that needs no renewal."""
        c = self.commands
        if isinstance(action, LaneChangeAction):
            return c.lane_change(tag, action, me, snap, self._entity_lanes())
        if isinstance(action, LaneOffsetAction):
            return c.lane_offset(tag, action, me, motion.offset, snap)
        if isinstance(action, FollowTrajectoryAction):
            return c.trajectory(tag, action, me, snap)
        if isinstance(action, TeleportAction):
            return c.teleport(tag, action, me, snap)
        if isinstance(action, SpeedProfileAction):
            return c.speed_profile(tag, action, me, snap)
        raise DirectorError(f"not supported yet ({type(action).__name__} in a story)")

    def _renew(self, snap: Snapshot) -> None:
        """The commands the truth steers every check (module doc)."""
        for tag, follow in list(self._follows.items()):
            motion = self._motion(follow.entity)
            assert motion is not None
            if snap.time < follow.after:
                continue  # its transition runs first
            me = snap.entities[follow.entity]
            action = follow.action
            cmd: TrackCommand | LateralCommand
            if isinstance(action, LateralDistanceAction):
                cmd, reached = self.commands.keep_lateral(follow, me, motion.offset, snap)
            else:
                cmd, reached = self.commands.follow(follow, me, snap, self._top[follow.entity],
                                                    CHECK_PERIOD)
            motion.command(cmd)
            if reached and isinstance(action, LongitudinalDistanceAction
                                      | LateralDistanceAction) and not action.continuous:
                del self._follows[tag]
                self._finish([tag], snap.time)
        for tag, sync in list(self._syncs.items()):
            motion = self._motion(sync.entity)
            assert motion is not None
            track, done = self.commands.sync_step(sync, snap, CHECK_PERIOD)
            motion.command(track)
            if done:
                del self._syncs[tag]
                motion.cancel(tag)  # it holds the final speed
                self._finish([tag], snap.time)
