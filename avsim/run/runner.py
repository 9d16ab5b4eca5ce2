"""The closed loop: world -> sensors -> stack -> joints, criteria on ground truth, recording.

Rates (the table `world.core.rates`; each divides the physics rate):
- the sensor loop (`avsim.run.sensor_loop`: every sensor, GNSS and odometry included) and
  the stack (decide-then-apply) at the control rate;
- criteria sample ground truth at the criteria rate (the control ticks' snapshots, so the
  log, the criteria and the NPC triggers share one projection of the ego onto the route),
  collisions (contact onsets) at the contact rate;
- the recording logs the ego pose, scalars and the plan at its rate, NPC boxes at theirs.

The criteria are the scenario's set (`avsim.criteria.registry`); a sample carries the NPCs'
true poses only when one of them needs them. After each sample the runner keeps the
infractions the criteria report (the result's `infractions`), and the recording logs each at
its sim time; the verdicts are logged at the end. The recording has a state lane per machine
of the plan (`planner.messages.MACHINES`), each from the state the first plan started in,
and the plan's `speed_source` as a lane of its own (what set the speed, tick by tick).

Each control tick decides on one snapshot (the sensor frames of this tick), then the
command is held on the joints for the control period's physics steps.

A scripted car under test (`EgoSpec.scripted`, `avsim run --ego scripted`) is moved by the
scenario's script (`world.ego.scripted`): no sensors are simulated and the stack never
runs; the log's stack columns then say the function is off (ACC off, lane keep, the driver's
speed source, NaN targets, no commands), its truth columns are the script's car.
"""

from __future__ import annotations

import math
import re
import time
from collections.abc import Callable, Mapping
from contextlib import suppress
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from avsim.criteria.base import (
    DECEL_WINDOW,
    MAX_LANE_CHANGE,
    CriterionResult,
    Infraction,
    Need,
    TruthSample,
    Verdict,
    judged_so_far,
)
from avsim.criteria.collision import NoCollision
from avsim.criteria.comfort import peaks
from avsim.criteria.declaration import RunInputs
from avsim.criteria.impulse import meets
from avsim.criteria.lane import TyresInLane
from avsim.criteria.registry import build_criteria
from avsim.criteria.route import Completes
from avsim.record.recorder import Recorder
from avsim.run.columns import Column, EnumColumn, Rows, flags, floats, ints
from avsim.run.holds import shortest_hold
from avsim.run.sensor_loop import FrameHook, SensorLoop, sensing_mode
from avsim.run.spill import SpillFile
from avsim.run.stack import build_stack, close_stack
from avsim.run.story import ScriptedStory, StoryboardStory, StoryEntry
from avsim.run.story_state import state_change_text
from avsim.run.storyboard.director import Director
from avsim.run.storyboard.state import StateChange as StoryStateChange
from avsim.run.verdict import RunError, RunVerdict
from avsim.scenario.scenario import Scenario
from avsim.stack.context import StackContext
from control.command import DrivingStack, StackStep, VehicleCommand
from planner.messages import MACHINES, AccMode, HazardLights, Motion, Plan, SpeedSource, StateChange
from world.core.rates import (
    ACTOR_RECORD_RATE,
    CONTACT_RATE,
    CONTROL_RATE,
    CRITERIA_RATE,
    PHYSICS_RATE,
    RECORD_RATE,
    TRIGGER_RATE,
)
from world.core.stopwatch import Stopwatch
from world.ego.body import vehicle_info
from world.frames import Indicator
from world.sensors.lidar import RayBackend
from world.sensors.pipeline import SensingError, SensingWorker
from world.sensors.setup import Profile, sensor_setup, sensor_specs
from world.spec import FlatTire
from world.truth import ego_lane_edges, time_to_collision, touching, vehicles_ahead
from world.world import World

MOVING = 2.0  # [m/s] the ego moves (`min_lead_gap`; `min_gap` judges from the same speed)
SETTLE_AFTER_DONE = 1.0  # [s] the run goes on this long after it may end: `completes`
#   reached and every required action and event fired

ProgressCallback = Callable[[float, float], None]  # (sim time, duration) [s]
StackFactory = Callable[[StackContext], DrivingStack]  # builds the stack of a run
T = TypeVar("T")
VERDICT_WORDS = {Verdict.PASS: "pass", Verdict.FAIL: "FAIL", Verdict.NOT_APPLICABLE: "n/a"}


@dataclass
class TrajectoryLog:
    """Per control tick: the ego's true and estimated state and what the stack did.

    Stored compactly and flat in memory (an hour's run holds 144,000 ticks, ~0.3 kB each):
    the columns (`avsim.run.columns`: numbers and flags as typed arrays, rows of numbers,
    the FSM states a byte each) keep their newest `CHUNK` values in memory and move older
    ones to the log's spill file, an unnamed temporary file that leaves nothing on disk
    (`avsim.run.spill`); every read sees the whole column. `array(name)` gives a column as a
    float64 array (a copy); `close()` frees the file (garbage collection does too), after
    which the spilled values cannot be read."""

    t: Column[float] = field(default_factory=floats)  # [s]
    x: Column[float] = field(default_factory=floats)  # [m] true, car centre
    y: Column[float] = field(default_factory=floats)  # [m]
    yaw: Column[float] = field(default_factory=floats)  # [rad]
    speed: Column[float] = field(default_factory=floats)  # [m/s] true forward speed
    station: Column[float] = field(default_factory=floats)  # [m] true centre station
    cross_track: Column[float] = field(default_factory=floats)  # [m] true centre offset from
    #   the centre of the lane the stack keeps (its plan's), left +
    lane_error: Column[float] = field(default_factory=floats)  # [m] true centre offset from the
    #   centre of the lane it is in (the truth and the map: `world.truth.ego_lane_edges`)
    crossing: Column[int] = field(default_factory=flags)  # its tyres are on or over a lane
    #   line (a lane change, from the truth: `avsim.criteria.lane.LaneChanges`)
    front_axle_error: Column[float] = field(default_factory=floats)  # [m] true, at front axle
    target_speed: Column[float] = field(default_factory=floats)  # [m/s]
    speed_limit: Column[float] = field(default_factory=floats)  # [m/s] at the front bumper
    steering: Column[float] = field(default_factory=floats)  # [rad] commanded
    drive_torque: Column[float] = field(default_factory=floats)  # [N m] commanded, total
    brake_torque: Column[float] = field(default_factory=floats)  # [N m] commanded, total
    wheel_spin: Rows = field(default_factory=Rows)  # [rad/s] (4,)
    acc_mode: EnumColumn[AccMode] = field(
        default_factory=partial(EnumColumn, AccMode))  # the ACC / event layer's mode
    motion: EnumColumn[Motion] = field(
        default_factory=partial(EnumColumn, Motion))  # the motion FSM's state
    hazard: Column[int] = field(default_factory=flags)  # the stack's hazard lights are on
    indicator: EnumColumn[Indicator] = field(
        default_factory=partial(EnumColumn, Indicator))  # the turn indicators, as commanded
    speed_source: EnumColumn[SpeedSource] = field(
        default_factory=partial(EnumColumn, SpeedSource))  # what set the speed
    lane: Column[int] = field(default_factory=ints)  # the lane the stack keeps (cross_track's)
    changing: Column[int] = field(default_factory=flags)  # a commanded lane change in hand
    pedal: Column[float] = field(default_factory=floats)  # [-] the driver's accelerator pedal
    pose_error: Column[float] = field(default_factory=floats)  # [m] the stack's position
    #   estimate (the plan's) from the true centre
    actor_station: Rows = field(default_factory=Rows)  # [m] (N,) true,
    #   along the road each drives on (the route; past an exit's fork, the road the route
    #   left for traffic that kept it; in a town, each actor's own route): not comparable
    #   with the ego's station off the route (the lead is `lead_gap`, `lead_speed`)
    actor_offset: Rows = field(default_factory=Rows)  # [m] (N,) true,
    #   from that road's reference line, left +
    lead_gap: Column[float] = field(default_factory=floats)  # [m] bumper gap to the vehicle
    #   ahead in the ego's lane (truth and map: `world.truth.vehicles_ahead`), NaN: none
    lead_speed: Column[float] = field(default_factory=floats)  # [m/s] its speed, NaN: none

    spill: SpillFile = field(default_factory=SpillFile, init=False, repr=False,
                             compare=False)  # where the columns move their older values

    def __post_init__(self) -> None:
        for column in vars(self).values():
            if isinstance(column, Column | Rows | EnumColumn):
                column.spill_to(self.spill)

    def array(self, name: str) -> NDArray[np.float64]:
        return np.array(getattr(self, name), dtype=np.float64)

    def close(self) -> None:
        """Free the spill file (idempotent)."""
        self.spill.close()


@dataclass(frozen=True, slots=True, eq=False)
class RunResult:
    scenario: Scenario
    criteria: list[CriterionResult]
    metrics: dict[str, float]
    sim_time: float  # [s]
    wall_time: float  # [s]
    log: TrajectoryLog
    recording: Path | None
    state_changes: tuple[StateChange, ...] = ()  # every FSM change, in time order
    infractions: tuple[Infraction, ...] = ()  # every infraction, in time order
    profile: str | None = None  # the sensor profile (None: map + GNSS only)
    renderer: str | None = None  # "egl" or "tiny" when cameras rendered
    stage_times: dict[str, float] = field(default_factory=dict)  # [s] wall time per stage
    #   (`world.core.stopwatch`: where the run's time went; not part of the result file)
    story: tuple[StoryEntry, ...] = ()  # each scripted action and event, and when it fired
    interrupted: bool = False  # stopped early by `Runner.interrupt` (a signal): the criteria
    #   are those judged so far (`avsim.criteria.base.judged_so_far`)
    error: RunError | None = None  # the exception that ended the run (verdict error): the
    #   criteria are those judged until then
    storyboard_state: tuple[StoryStateChange, ...] = ()  # an OpenSCENARIO storyboard's
    #   variables, parameters and environments set, in time order

    @property
    def verdict(self) -> RunVerdict:
        """Error, else interrupted, else fail if a criterion failed, else pass
        (`avsim.run.verdict`)."""
        if self.error is not None:
            return RunVerdict.ERROR
        if self.interrupted:
            return RunVerdict.INTERRUPTED
        return RunVerdict.FAIL if any(c.failed for c in self.criteria) else RunVerdict.PASS

    @property
    def passed(self) -> bool:
        """The run went to its end and no criterion failed (one not applicable does not
        fail the run); an interrupted run or one that ended in error has not passed."""
        return self.verdict is RunVerdict.PASS


MAX_CHANNELS = 64  # a stack's diagnostic channels, at most
CHANNEL = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,63}$")  # a channel's name


def stack_channels(channels: Mapping[str, float]) -> dict[str, float]:
    """A stack's diagnostic channels as the recording's scalars, ``stack/<name>``; a
    `ValueError` (the run's error) for more than ``MAX_CHANNELS``, a name that is not
    ``CHANNEL`` or a value that is not a number."""
    if len(channels) > MAX_CHANNELS:
        raise ValueError(f"the stack gave {len(channels)} diagnostic channels (at most "
                         f"{MAX_CHANNELS})")
    out: dict[str, float] = {}
    for name, value in channels.items():
        if not isinstance(name, str) or not CHANNEL.match(name):
            raise ValueError(f"diagnostic channel {name!r}: a name is a letter, then letters, "
                             "digits or _ (at most 64)")
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ValueError(f"diagnostic channel {name}: {value!r} is not a number")
        out[f"stack/{name}"] = float(value)
    return out


class Runner:
    """Runs one scenario to its end (duration, or `completes` reached) and judges it."""

    def __init__(self, scenario: Scenario, recording: Path | None = None,
                 profile: Profile | None = Profile.DEFAULT, sensing: str = "auto",
                 frame_hook: FrameHook | None = None,
                 lidar_backend: RayBackend = RayBackend.EMBREE,
                 stack: StackFactory | None = None) -> None:
        """`profile`: the sensor set-up (None: no cameras or LiDAR, the stack drives on
        GNSS + odometry and the map); `sensing`: where cameras render ('auto', 'inline' or
        'process', see `world.sensors.pipeline`); `frame_hook`: alters the camera frames the stack
        gets (fault injection in tests); `lidar_backend`: what casts the LiDAR's rays (Embree,
        or Bullet's own ray test to compare with); `stack`: builds the stack that drives
        the car instead of the one the scenario chooses (an agent's, `avsim.gym`)."""
        self.scenario = scenario
        spec = scenario.world
        self.scripted = spec.ego.scripted  # the script moves the ego: no sensors, no stack
        if self.scripted:
            profile = None
        self.setup = sensor_setup(profile, spec.sensors.lidar) if profile is not None else None
        mode = sensing_mode(sensing)
        # the sensing worker builds its mirror world while this process builds its own
        worker = SensingWorker(spec, self.setup) \
            if mode == "process" and self.setup is not None and self.setup.cameras else None
        try:
            self._build(scenario, recording, mode, frame_hook, lidar_backend, worker, stack)
        except BaseException:
            if worker is not None:
                worker.close()
            if (stack := getattr(self, "stack", None)) is not None:
                with suppress(Exception):  # the build's exception is the one to raise
                    close_stack(stack)  # built before a later part raised: its process ended
            if (world := getattr(self, "world", None)) is not None:
                with suppress(Exception):  # the build's exception is the one to raise
                    world.close()  # built before a later part raised: its server freed
            raise

    def _build(self, scenario: Scenario, recording: Path | None, mode: str,
               frame_hook: FrameHook | None, lidar_backend: RayBackend,
               worker: SensingWorker | None, stack: StackFactory | None) -> None:
        spec = scenario.world
        privileged = scenario.stack.privileged  # the truth sensor is on the car
        self.world = World(spec, self.setup, cameras=mode == "inline",
                           lidar_backend=lidar_backend, privileged=privileged)
        w = self.world
        self.car = w.ego.geometry
        self.watch = Stopwatch()  # where the run's wall time goes, stage by stage
        make = stack if stack is not None else partial(build_stack, scenario.stack)
        self.stack = make(StackContext(
            road=w.road, vehicle=vehicle_info(self.car),
            sensors=sensor_specs(self.setup, privileged), start_lane=spec.ego.lane,
            set_speed=scenario.driver.set_speed, max_speed=spec.ego.max_speed,
            overtake=scenario.driver.overtake, seed=spec.seed, timer=self.watch))
        self.log = TrajectoryLog()
        names = {b: "building or sign" for b in w.scene.obstacle_bodies}
        names.update({b: "kerb" for b in w.scene.kerb_bodies})
        names.update({b: f"actor {a.id}" for b, a in zip(w.actors.bodies, spec.actors,
                                                          strict=True)})
        lane_change = scenario.criteria.get("lane_change")
        self.director = Director(scenario.story, w) if scenario.story is not None else None
        self.story: ScriptedStory | StoryboardStory = (
            ScriptedStory(scenario, w) if self.director is None
            else StoryboardStory(self.director))
        self.criteria = build_criteria(scenario.criteria, RunInputs(
            road=w.road, car=self.car, rate=CRITERIA_RATE.hz, signals=w.signals,
            set_speed=scenario.driver.set_speed, bodies=names,
            actor_bodies={b: a.id for b, a in zip(w.actors.bodies, spec.actors, strict=True)},
            lane_change_max=getattr(lane_change, "max_duration", MAX_LANE_CHANGE),
            story=tuple(e.label for e in self.story.entries if not e.optional),
            story_off={e.label: e.off for e in self.story.entries if e.off is not None},
            town=spec.town,
            parameters=scenario.story.scenario.parameters if scenario.story else {}))
        self.completes = next((c for c in self.criteria.items if isinstance(c, Completes)),
                              None)  # reached (and the story played out): the run may end;
        #   None (`completes: false`): it runs to its duration
        self.collisions = self.criteria.find(NoCollision)  # its count is a metric
        self.lanes = self.criteria.find(TyresInLane).lanes  # the truth's lane changes
        self.infractions: list[Infraction] = []
        self._story_logged = 0  # storyboard state changes already in the recording
        self.recorder = Recorder(recording, recording_name=scenario.name) if recording else None
        self.sensors = SensorLoop(w, self.setup, self.stack, mode, self.recorder, frame_hook,
                                  self.watch, worker)
        self.state_changes: list[StateChange] = []
        self._touching: frozenset[int] = frozenset()
        self._last: StackStep | None = None
        self._interrupted = False  # a signal asked the run to end
        self._stopped = False  # the run ended early for it (not after its last tick)
        self.error: RunError | None = None  # the exception that ended the run, if one did
        self._sim_time = 0.0  # [s] when the run ended (set as it closes)
        self._closing = False
        self._steps = round(scenario.duration * PHYSICS_RATE)  # the duration's physics steps
        self._done_at: float | None = None  # [s] when the run first might end
        self._started = time.perf_counter()  # [s] wall clock at `start`
        self._ended = False  # the run is over: `advance` does nothing more
        self._result: RunResult | None = None  # `finish`'s, once made

    def interrupt(self) -> None:
        """End the run at the current tick (safe from a signal handler): `run` closes the
        recording and returns what was judged so far, marked interrupted."""
        self._interrupted = True

    # -- the loop ------------------------------------------------------------------------------

    def run(self, progress: ProgressCallback | None = None) -> RunResult:
        """Run to the end (duration, `completes` reached, a StopTrigger) and judge the run:
        `start`, `advance` until it says the run is over, `finish`.

        Never raises for what a stage does wrong: an exception in any stage (the sensors and
        perception, the planner, control, the storyboard, a criterion, the recorder, the
        world) ends the run at that tick with verdict error (`RunResult.error`: its type,
        message, traceback and sim time [s]); the criteria are those judged so far, the
        recording logs the error as an event at its sim time and is closed whole."""
        try:
            if self.start():
                while self.advance(progress):
                    pass
        finally:
            result = self.finish()
        return result

    def start(self) -> bool:
        """Begin the run, step-wise: the static recording and the storyboard's first check
        (t = 0). Returns whether the run may go on (False: it ended in error, `finish`
        says which)."""
        self._started = time.perf_counter()
        try:
            self._begin()
        except Exception as exc:  # a stage's bug ends this run, not the program
            self._ended_by(exc)
            self._ended = True
        return not self._ended

    def advance(self, progress: ProgressCallback | None = None) -> bool:
        """One control period: decide on this snapshot (`_tick`), then hold the command on
        the joints for the period's physics steps (`_period`). Returns whether the run may
        go on; False once it is over (its duration, it settled after it may end, a
        StopTrigger, `interrupt`, or an exception, kept as the run's error). Each call after
        the end does nothing and returns False."""
        if self._ended:
            return False
        try:
            going = self._advance(progress)
        except Exception as exc:  # a stage's bug ends this run, not the program
            self._ended_by(exc)
            going = False
        self._ended = not going
        return going

    def finish(self) -> RunResult:
        """Close what the run opened and judge it (idempotent: a second call returns the
        same result)."""
        if self._result is not None:
            return self._result
        self._ended = True
        criteria = self._close()
        renderer = self.sensors.sensing.renderer
        metrics: dict[str, float] = self._attempt(self._metrics, {})
        story: tuple[StoryEntry, ...] = self._attempt(self.story.now, ())
        self._result = RunResult(
            scenario=self.scenario, criteria=criteria, metrics=metrics,
            sim_time=self._sim_time, wall_time=time.perf_counter() - self._started,
            log=self.log, recording=self.recorder.path if self.recorder else None,
            state_changes=tuple(self.state_changes), infractions=tuple(self.infractions),
            profile=self.setup.profile.value if self.setup is not None else None,
            renderer=renderer.value if renderer is not None else None,
            stage_times=dict(self.watch.seconds), story=story,
            interrupted=self._stopped, error=self.error,
            storyboard_state=self._story_state(),
        )
        return self._result

    @property
    def failed_so_far(self) -> bool:
        """A criterion has failed by now, or the car has touched something (truth)."""
        return self.collisions.count > 0 or any(
            c.first_failure is not None for c in self.criteria.items)

    def _story_state(self) -> tuple[StoryStateChange, ...]:
        """The storyboard's state changes so far (none without a storyboard)."""
        if self.director is None:
            return ()
        return tuple(self.director.runtime.story_state.changes)

    def _begin(self) -> None:
        """The static recording and the storyboard's first check, t = 0."""
        if self.recorder is not None:
            with self.watch("recording"):
                self._record_static()
        if self.director is not None:
            with self.watch("runner"):
                self.director.step()

    def _advance(self, progress: ProgressCallback | None) -> bool:
        """One control period (`advance`), exceptions raised; whether the run goes on."""
        w = self.world
        if w.clock.step >= self._steps:
            return False
        if self._interrupted:
            self._stopped = True
            return False
        self._tick()
        self._period(self._steps)
        if self._done_at is None and self._may_end():
            self._done_at = w.t
        if self._over(self._done_at):
            return False
        if progress is not None and w.clock.step % PHYSICS_RATE == 0:
            progress(w.t, self.scenario.duration)
        return w.clock.step < self._steps

    def _ended_by(self, exc: Exception) -> None:
        """The run ended by `exc`: its error, unless it was being interrupted and `exc` is
        the sensing worker's end (Ctrl-C reaches the whole process group, and a worker
        still starting, before it ignores the signal, exits on it): then it is interrupted."""
        if self._interrupted and isinstance(exc, SensingError):
            self._stopped = True
            return
        self._failed(exc)

    def _failed(self, exc: BaseException) -> None:
        """The run ended in error with `exc` (only the first error is kept)."""
        if self.error is None:
            self.error = RunError.of(exc, self._sim_time if self._closing else self.world.t)

    def _attempt(self, step: Callable[[], T], otherwise: T) -> T:
        """`step()`, or `otherwise` when it raises (the run then ends in error with it)."""
        try:
            return step()
        except Exception as exc:  # a bug while closing or judging ends the run in error
            self._failed(exc)
            return otherwise

    def _close(self) -> list[CriterionResult]:
        """Close what the run opened, each even if one before failed: the sensors, the
        stack (its optional `close`), the recording (the verdicts and any error logged first,
        so the file is whole), the world. Returns the criteria's results, judged so far when
        the run ended early."""
        self._sim_time, self._closing = self.world.t, True
        self._attempt(self.sensors.close, None)
        self._attempt(partial(close_stack, self.stack), None)
        criteria: list[CriterionResult] = self._attempt(self._judged, [])
        if self.recorder is not None:
            with self.watch("recording"):
                self._attempt(partial(self._record_end, criteria), None)
                self._attempt(self.recorder.close, None)
        self._attempt(self.world.close, None)
        return criteria

    def _judged(self) -> list[CriterionResult]:
        """The criteria's results; judged so far (`judged_so_far`) if the run ended early."""
        criteria = self.criteria.results()
        if self.error is not None:
            return judged_so_far(criteria, self._sim_time, "the run ended in error")
        if self._stopped:
            return judged_so_far(criteria, self._sim_time)
        return criteria

    def _period(self, steps: int) -> None:
        """The physics steps of one control period (at most up to `steps`), with the
        storyboard's director and the contact watch at their rates."""
        w, watch = self.world, self.watch
        for _ in range(min(CONTROL_RATE.every, steps - w.clock.step)):
            with watch("physics"):
                w.step()
            if self.director is not None and TRIGGER_RATE.fires(w.clock.step):
                with watch("runner"):
                    self.director.step()
            if w.clock.step % CONTACT_RATE.every == 0:
                with watch("criteria"):
                    self._watch(w.clock.step)

    def _over(self, done_at: float | None) -> bool:
        """The run ends: an OpenSCENARIO file's StopTrigger fired, or it settled after it
        may end (`done_at`)."""
        if self.director is not None and self.director.ended:
            return True
        return done_at is not None and self.world.t >= done_at + SETTLE_AFTER_DONE

    def _may_end(self) -> bool:
        """`completes` is reached and every required action and event has fired."""
        return (self.completes is not None and self.completes.done
                and all(e.optional or e.label in self.story.fired for e in self.story.entries))

    def _tick(self) -> None:
        """A control tick: the sensors' frames due now reach the stack, then decide and
        apply."""
        w, watch = self.world, self.watch
        if self.scripted:
            with watch("runner"):
                self._log_scripted()
            if self.recorder is not None and RECORD_RATE.fires(w.clock.step):
                with watch("recording"):
                    self._record_scripted()
            return
        self.sensors.tick()
        out = self.stack.tick(w.t, CONTROL_RATE.period)
        cmd = out.command
        w.ego.apply(cmd.steering_angle, cmd.drive_torque, cmd.brake_torque)
        w.ego.set_hazard_lights(cmd.hazard_lights)
        w.ego.set_indicator(cmd.indicator)
        previous, self._last = self._last, out
        with watch("runner"):
            self._log_tick(out)
            if out.plan is not None:
                self.state_changes.extend(out.plan.changes)
        if self.recorder is not None:
            with watch("recording"):
                self._record_plan(out, previous)

    def _record_plan(self, out: StackStep, previous: StackStep | None) -> None:
        """The tick's plan in the recording: the machines' lanes (their initial states at
        the first tick), the tick's series at the recording rate, each state change and the
        speed source when it changes; a stack that shows no plan, its channels only."""
        rec, w = self.recorder, self.world
        assert rec is not None
        plan, before = out.plan, previous.plan if previous is not None else None
        if RECORD_RATE.fires(w.clock.step):
            self._record_tick(out)
        if plan is None:
            return
        if previous is None:
            self._record_machines(plan)
        for change in plan.changes:
            rec.log_state(change.t, change.machine, change.target, change.reason)
        if before is not None and before.speed_source is not plan.speed_source:
            rec.log_state(w.t, "speed_source", plan.speed_source.value, text=False)  # an
            #   attribution, not a state change

    def _log_tick(self, out: StackStep) -> None:
        """The tick's row: the truth (against the lane the plan keeps, else the lane the
        car is in) and the stack's (NaN, or the function-off states, where it shows no
        plan)."""
        plan, w, log = out.plan, self.world, self.log
        if plan is None:
            self._log_unplanned(out)
            return
        truth = w.ego_truth
        pose_error = math.hypot(plan.ego.x - float(truth.position[0]),
                                plan.ego.y - float(truth.position[1]))
        self._log_truth(plan.lane)  # computed and appended first: the row whole or absent
        log.target_speed.append(plan.target_speed)
        log.speed_limit.append(plan.speed_limit)
        self._log_command(out.command)
        log.acc_mode.append(plan.acc_mode)
        log.hazard.append(plan.hazard is HazardLights.ON)
        log.motion.append(plan.motion)
        log.speed_source.append(plan.speed_source)
        log.lane.append(plan.lane)
        log.changing.append(plan.lane != plan.origin_lane)
        log.pose_error.append(pose_error)

    def _log_unplanned(self, out: StackStep) -> None:
        """The row of a stack that shows no plan: the truth against the lane the car is in,
        its command, and no plan (NaN targets and pose error, no ACC, lane keeping)."""
        lane = self._lane_in()
        self._log_truth(lane)
        log = self.log
        log.target_speed.append(math.nan)
        log.speed_limit.append(math.nan)
        self._log_command(out.command)
        log.acc_mode.append(AccMode.ACC_OFF)
        log.hazard.append(out.command.hazard_lights)
        log.motion.append(Motion.LANE_KEEP)
        log.speed_source.append(SpeedSource.SET_SPEED)
        log.lane.append(lane)
        log.changing.append(False)
        log.pose_error.append(math.nan)

    def _log_command(self, command: VehicleCommand) -> None:
        """The command's columns of the tick's row: steering, torques, indicators."""
        log = self.log
        log.steering.append(command.steering_angle)
        log.drive_torque.append(command.drive_torque)
        log.brake_torque.append(command.brake_torque)
        log.indicator.append(command.indicator)

    def _lane_in(self) -> int:
        """The lane the car's centre is in (the last one logged when it is off the lanes)."""
        route = self.world.ego_route
        found = self.world.road.lane_of(route.station, float(route.offsets[0]))[0]
        if found is not None:
            return int(found)
        return self.log.lane[-1] if len(self.log.lane) else self.world.spec.ego.lane

    def _log_scripted(self) -> None:
        """A scripted ego's row (module doc): the truth against the lane it is in."""
        w, log = self.world, self.log
        route = w.ego_route
        assert w.scripted is not None
        found = w.road.lane_of(route.station, float(route.offsets[0]))[0]
        lane = found if found is not None else w.scripted.motion.lane  # off the lanes
        self._log_truth(lane)
        for column in (log.target_speed, log.speed_limit, log.drive_torque, log.brake_torque):
            column.append(math.nan)
        log.steering.append(0.0)
        log.acc_mode.append(AccMode.ACC_OFF)
        log.hazard.append(False)
        log.indicator.append(Indicator.OFF)
        log.motion.append(Motion.LANE_KEEP)
        log.speed_source.append(SpeedSource.DRIVER)
        log.lane.append(lane)
        log.changing.append(False)
        log.pose_error.append(0.0)  # no estimate: the truth is the script's

    def _log_truth(self, lane_index: int) -> None:
        """The truth columns of the tick's row; cross-track errors from lane `lane_index`."""
        w, log = self.world, self.log
        truth, route = w.ego_truth, w.ego_route
        s = route.station
        lane = self.world.road.lane(lane_index)
        r, r_fa = (route.offsets[:2] - lane.offset_at(route.stations[:2])).tolist()
        lo, hi = ego_lane_edges(w.road, s, float(route.offsets[0]))
        ahead = vehicles_ahead(w.road, w.actors.poses, s, float(route.offsets[0]),
                               self.car.body_length) if w.actors.bodies else ()
        actor_station = np.array([m.s for m in w.actors.motions])
        actor_offset = np.array([m.offset for m in w.actors.motions])
        crossing = self.lanes.crossing is not None
        log.t.append(w.t)
        log.x.append(float(truth.position[0]))
        log.y.append(float(truth.position[1]))
        log.yaw.append(truth.yaw)
        log.speed.append(truth.speed)
        log.station.append(s)
        log.cross_track.append(r)
        log.front_axle_error.append(r_fa)
        log.wheel_spin.append(truth.wheel_spin.copy())
        log.pedal.append(w.accelerator_pedal)
        log.lane_error.append(float(route.offsets[0]) - 0.5 * (lo + hi))
        log.crossing.append(crossing)
        log.actor_station.append(actor_station)
        log.actor_offset.append(actor_offset)
        log.lead_gap.append(ahead[0].gap if ahead else math.nan)
        log.lead_speed.append(ahead[0].speed if ahead else math.nan)

    def _watch(self, step: int) -> None:
        """Criteria: contact onsets at the contact rate, the rest at the criteria rate."""
        w = self.world
        now = frozenset(touching(w.client, w.ego.body, w.scene.ground)) - w.scene.bump_bodies
        if now != self._touching:
            self._touching = now
            self._sample()
        elif CRITERIA_RATE.fires(step):
            self._sample()

    def _sample(self) -> None:
        """The criteria see the truth now (with the NPCs' poses only when one needs them);
        the infractions they report are kept and logged at their time."""
        w = self.world
        truth, route = w.ego_truth, w.ego_route
        actors = w.actors.poses if Need.ACTORS in self.criteria.needs else None
        self.story.update()
        infractions = self.criteria.update(TruthSample(
            t=w.t, speed=truth.speed, station=route.station,
            front_station=route.station + self.car.front_overhang,
            tyres=route.tyres, tyre_stations=route.tyre_stations,
            tyre_offsets=route.tyre_offsets, touching=self._touching,
            offset=float(route.offsets[0]), actors=actors,
            lateral_accel=truth.speed * truth.yaw_rate,
            road_curvature=float(w.road.curvature_at(route.station)),
            rear_station=route.station - self.car.body_length / 2,
            axle_stations=(float(route.stations[1]),
                           float(np.mean(route.stations[4:6]))),
            flat=self._flat_fired(), hazard_lights=w.ego.hazard_lights, fired=self.story.fired,
            sensor_fault=bool(w.sensor_faults),
            xy=(float(truth.position[0]), float(truth.position[1])),
        ))
        self.infractions += infractions
        if self.recorder is not None:
            for i in infractions:
                self.recorder.log_infraction(i.t, i.kind, i.message, i.where)
            self._record_story_state()

    def _record_story_state(self) -> None:
        """The storyboard's state changes since the last sample, as event lines."""
        assert self.recorder is not None
        changes = self._story_state()
        for change in changes[self._story_logged:]:
            self.recorder.log_event(change.t, state_change_text(change))
        self._story_logged = len(changes)

    def _flat_fired(self) -> bool:
        """A flat tyre event has happened to the ego (truth, for `completes`)."""
        return any(t is not None and isinstance(e.event, FlatTire)
                   for t, e in zip(self.world.event_fired_at, self.scenario.world.events,
                                   strict=True))

    # -- results -------------------------------------------------------------------------------

    def _metrics(self) -> dict[str, float]:
        """The run's metrics. Every contact onset is in `collisions`, those a rule excused
        in `collisions_excused` too. The decelerations and jerks leave out the contacts'
        impulses (`avsim.criteria.impulse`): `max_decel` [m/s^2] is the car's braking,
        `max_decel_with_contact` the raw peak, the impulse in."""
        keeping = ~np.asarray(self.log.crossing, dtype=bool)  # lane changes are not errors
        xte = self.log.array("lane_error")[keeping]
        speed, t = self.log.array("speed"), self.log.array("t")
        impulses = self.collisions.impulses.spans
        raw, braking = _max_decel(t, speed, impulses)
        return {
            "max_lateral_error": float(np.max(np.abs(xte))) if len(xte) else math.nan,
            "rms_lateral_error": float(np.sqrt(np.mean(xte**2))) if len(xte) else math.nan,
            "max_front_axle_error":
                float(np.max(np.abs(self.log.array("front_axle_error")[keeping])))
            if len(xte) else math.nan,
            "max_decel": braking,
            "max_decel_with_contact": raw,
            "pose_rmse": float(np.sqrt(np.mean(self.log.array("pose_error") ** 2)))
            if len(speed) else math.nan,
            "max_speed": float(np.max(speed)) if len(speed) else 0.0,
            "distance": float(self.log.station[-1] - self.log.station[0]) if xte.size else 0.0,
            "collisions": float(self.collisions.count),
            "collisions_excused": float(self.collisions.excused),
            "acc_shortest_mode": shortest_hold(self.state_changes, "acc"),
        } | self._lead_margins() | peaks(t, speed, impulses) \
            | (self.sensors.metrics() if self.setup is not None else {})

    def _lead_margins(self) -> dict[str, float]:
        """The closest the ego came to the vehicle ahead in its lane, from the truth
        (`world.truth.vehicles_ahead`): the least bumper gap while the ego moved (faster than
        `MOVING`) and the least time to collision; NaN where there was none."""
        gap, speed = self.log.array("lead_gap"), self.log.array("speed")
        ttc = time_to_collision(gap, speed, self.log.array("lead_speed"))
        moving = gap[np.isfinite(gap) & (speed > MOVING)]
        return {"min_lead_gap": float(np.min(moving)) if moving.size else math.nan,
                "min_ttc": float(np.nanmin(ttc)) if np.isfinite(ttc).any() else math.nan}

    # -- recording -----------------------------------------------------------------------------

    def _record_static(self) -> None:
        rec, w = self.recorder, self.world
        assert rec is not None
        rec.log_road_meshes(w.scene.road_meshes)
        if w.scene.buildings:
            b = w.scene.buildings
            quats = [[0.0, 0.0, math.sin(x.yaw / 2), math.cos(x.yaw / 2)] for x in b]
            rec.log_static_boxes("/world/buildings", [x.centre for x in b],
                                 [x.half_extents for x in b], quats,
                                 (np.array([x.rgb for x in b]) * 255).astype(np.uint8))
        g = self.car
        r = g.wheel_radius
        wheels = [[g.front_axle, g.track / 2, 0.0], [g.front_axle, -g.track / 2, 0.0],
                  [-g.rear_axle, g.track / 2, 0.0], [-g.rear_axle, -g.track / 2, 0.0]]
        half_height = (g.body_height - g.ground_clearance) / 2  # the body as one box
        rec.log_ego_body(body_half_size=(g.body_length / 2, g.body_width / 2, half_height),
                         body_center=(0.0, 0.0, g.ground_clearance + half_height - r),
                         wheel_centers=wheels, wheel_radius=r, wheel_half_width=g.tyre_width / 2)
        lanes = [np.column_stack([lane.position(np.linspace(0, w.road.length, 400), 0.0),
                                  np.full(400, 0.02)]) for lane in w.road.lanes]
        rec.log_static_lines("/world/map/lanes", lanes, (90, 160, 255), 0.03)

    def _record_machines(self, plan: Plan) -> None:
        """A lane per state machine of the plan, each from the state it starts in: the
        first plan's, or what its first change left."""
        rec = self.recorder
        assert rec is not None
        left = {c.machine: c.source for c in reversed(plan.changes)}
        for machine, states in MACHINES.items():
            rec.log_state_machine(machine, [x.value for x in states])
            initial = left.get(machine, plan.states[machine].value)
            rec.log_state(0.0, machine, initial, "initial state")

    def _record_tick(self, out: StackStep) -> None:
        rec, w = self.recorder, self.world
        assert rec is not None
        truth, log = w.ego_truth, self.log
        rec.log_ego_pose(w.t, truth.position, truth.quaternion)
        rec.log_scalars(w.t, {
            "speed": truth.speed, "target_speed": log.target_speed[-1],
            "speed_limit": log.speed_limit[-1], "steering": out.command.steering_angle,
            "cross_track_error": log.cross_track[-1],
            "lead_gap": log.lead_gap[-1], "lead_speed": log.lead_speed[-1],  # NaN: no lead
        })
        if out.channels:
            rec.log_scalars(w.t, stack_channels(out.channels))
        if out.plan is not None:
            rec.log_path(w.t, out.plan.path.xy)
        self._record_actors()

    def _record_scripted(self) -> None:
        """A scripted ego's tick in the recording: its pose, the truth's scalars, the NPCs
        (no plan, no commands); the first says the script drives it."""
        rec, w = self.recorder, self.world
        assert rec is not None
        truth, log = w.ego_truth, self.log
        if len(log.t) == 1:
            rec.log_event(w.t, "the car under test is scripted: the scenario's actions move "
                               "it, the stack does not drive", "INFO")
        rec.log_ego_pose(w.t, truth.position, truth.quaternion)
        rec.log_scalars(w.t, {"speed": truth.speed, "cross_track_error": log.cross_track[-1],
                              "lead_gap": log.lead_gap[-1], "lead_speed": log.lead_speed[-1]})
        self._record_actors()

    def _record_actors(self) -> None:
        """The NPC boxes, at their recording rate."""
        rec, w = self.recorder, self.world
        assert rec is not None
        if ACTOR_RECORD_RATE.fires(w.clock.step):
            p = w.actors.poses
            quats = np.column_stack([np.zeros((len(p.yaws), 2)), np.sin(p.yaws / 2),
                                     np.cos(p.yaws / 2)])
            rec.log_actors(w.t, p.ids, p.centres, p.half_sizes, quats,
                           [k.value for k in p.kinds])

    def _record_end(self, criteria: list[CriterionResult]) -> None:
        """The run's end in the recording: the error that ended it (at its sim time), the
        perception scores and each criterion's verdict."""
        rec = self.recorder
        assert rec is not None
        if self.error is not None:
            rec.log_event(self.error.sim_time, self.error.line(), "ERROR")
        if self.setup is not None:
            scores = ", ".join(f"{k} {v:.3f}" for k, v in self.sensors.metrics().items())
            rec.log_event(self._sim_time, f"perception against the truth: {scores}", "INFO")
        for r in criteria:
            level = "ERROR" if r.failed else "INFO"
            t = r.first_failure if r.first_failure is not None else self._sim_time
            value = "none" if r.value is None else f"{r.value:.3f} {r.unit}"
            note = f"; {r.note}" if r.note else ""
            rec.log_event(t, f"criterion {r.name}: {VERDICT_WORDS[r.verdict]} (value {value}, "
                             f"threshold {r.threshold} {r.unit}{note})", level)


def _max_decel(t: NDArray[np.float64], speed: NDArray[np.float64],
               impulses: list[tuple[float, float]]) -> tuple[float, float]:
    """([m/s^2] the peak deceleration on a `DECEL_WINDOW` moving average of the logged
    speeds (control rate), [m/s^2] the same leaving out the windows that meet a contact's
    impulse, `avsim.criteria.impulse`); 0 where there is none."""
    dt = CONTROL_RATE.period
    window = max(1, round(DECEL_WINDOW / dt))
    if len(speed) <= window:  # no window filled
        return 0.0, 0.0
    decel = -np.diff(speed) / dt
    smooth = np.convolve(decel, np.ones(window) / window, mode="valid")
    kept = [d for k, d in enumerate(smooth.tolist())
            if not meets(impulses, float(t[k]), float(t[k + window]))]
    return float(max(0.0, np.max(smooth))), max([0.0, *kept])
