"""`AvsimEnv`: a scenario (or a campaign family) as a Gymnasium environment.

The agent drives the car under test in place of the stack: each `step` holds its action
(road-wheel angle [rad], longitudinal acceleration [m/s^2]) for `action_repeat` control
periods (40 Hz) through the car's drive-by-wire interface and wheel joints, as a user's
stack would (`avsim.gym.agent`). The world, the storyboard and the criteria run as in
`avsim run` (the runner's step-wise form, `avsim.run.runner.Runner.advance`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, SupportsFloat, cast

import gymnasium
import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from avsim.gym.agent import Action, AgentStack
from avsim.gym.reward import StepOutcome, reward
from avsim.gym.sensors import SensorObservation
from avsim.gym.source import MAX_EPISODE_SEED, ScenarioSource
from avsim.gym.truth import TruthObservation
from avsim.run.runner import Runner
from avsim.stack import StackContext
from vehicle_urdf import read_geometry
from world.core.rates import CONTROL_RATE
from world.ego.body import vehicle_info
from world.frames import CameraFrame
from world.sensors.setup import Profile, sensor_setup, sensor_specs

Observation = dict[str, NDArray[np.generic]]
MIN_ACCEL = -8.0  # [m/s^2] the strongest braking an action asks
MAX_ACCEL = 4.0  # [m/s^2] the strongest drive an action asks
OBSERVATIONS = ("sensors", "truth")
PROFILES = ("none", "fast", "default", "paper")
MAX_ACTION_REPEAT = 400  # control periods per step, at most (10 s)
MAX_NEAREST = 64  # actor rows of the truth observation, at most


class AvsimEnv(gymnasium.Env[Observation, NDArray[np.float32]]):
    """A scenario file, bundled name or campaign family as an episode (docs/stack-api.md,
    "Gymnasium").

    - `reset(seed=...)`: a new run. A family draws a concrete scenario from its `vary:` laws
      with the episode's seed (`avsim.gym.source`); a fixed scenario takes it as its `seed`.
      Same seed, same episode, bit for bit. The first control period runs with the wheels
      straight and no acceleration, so the first observation holds the frames of t = 0.
    - action: float32 [road-wheel angle [rad] (left +) within the car's limit,
      acceleration [m/s^2] within [-8, 4]], held for `action_repeat` control periods of
      0.025 s; it acts from the next control period after the frames observed.
    - observation (`observation=`): `sensors`, the newest frame of each sensor of the
      `profile` (`avsim.gym.sensors`; profile `none`: GNSS and odometry only), or `truth`,
      the car's and its `nearest` neighbours' true state (`avsim.gym.truth`), privileged.
    - reward [m]: progress along the route, minus the lane offset and the change of the
      asked acceleration, minus 100 once on a failure (`avsim.gym.reward`).
    - `terminated`: a criterion failed, the car touched something, or the run ended in
      error (`info["error"]`); `truncated`: the scenario ended otherwise (its duration, its
      route completed and settled, a StopTrigger).
    - `info`: `t` [s], `privileged`, `failed` (the criteria failed so far), `collisions`,
      and at the episode's end `verdict` and `error` (None, or the run's error line).
    - `render()` (`render_mode="rgb_array"`): the front camera's newest image, if the
      profile has one, else None.
    """

    metadata: dict[str, Any] = {  # noqa: RUF012 (Gymnasium reads it from the class)
        "render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, scenario: str | Path, *, overrides: dict[str, object] | None = None,
                 profile: str = "none", observation: str = "sensors", action_repeat: int = 4,
                 seed: int | None = None, nearest: int = 8, render_mode: str | None = None,
                 search_paths: tuple[Path, ...] = ()) -> None:
        if profile not in PROFILES:
            raise ValueError(f"profile {profile!r}: one of {', '.join(PROFILES)}")
        if observation not in OBSERVATIONS:
            raise ValueError(f"observation {observation!r}: one of {', '.join(OBSERVATIONS)}")
        if not 1 <= action_repeat <= MAX_ACTION_REPEAT:
            raise ValueError(f"action_repeat {action_repeat}: 1 to {MAX_ACTION_REPEAT}")
        if not 1 <= nearest <= MAX_NEAREST:
            raise ValueError(f"nearest {nearest}: 1 to {MAX_NEAREST}")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode {render_mode!r}: None or 'rgb_array'")
        self.source = ScenarioSource(scenario, overrides, search_paths)
        self.profile = None if profile == "none" else Profile(profile)
        self.observation = observation
        self.action_repeat = action_repeat
        self.render_mode = render_mode
        self._seed = seed
        specs = sensor_specs(sensor_setup(self.profile) if self.profile is not None else None)
        self._sensors = SensorObservation(specs)
        self._truth = TruthObservation(nearest, action_repeat * CONTROL_RATE.period)
        self.observation_space = cast(spaces.Space[Observation], self._sensors.space
                                      if observation == "sensors" else self._truth.space)
        limit = vehicle_info(read_geometry()).max_steer  # [rad]
        self.actions = spaces.Box(np.array([-limit, MIN_ACCEL], np.float32),
                                       np.array([limit, MAX_ACCEL], np.float32),
                                       dtype=np.float32)
        self.action_space = self.actions
        self.runner: Runner | None = None
        self.agent: AgentStack | None = None
        self._accel = 0.0  # [m/s^2] the last asked acceleration
        self._going = False  # the run may go on
        self._over = False  # the episode has ended (its run finished)

    # -- Gymnasium ------------------------------------------------------------------------------

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[Observation, dict[str, Any]]:
        if seed is None and self._seed is not None:
            seed, self._seed = self._seed, None  # the constructor's seed: the first reset's
        super().reset(seed=seed)
        self._end_run()
        episode_seed = int(self.np_random.integers(0, MAX_EPISODE_SEED, endpoint=True))
        self.runner = Runner(self.source.scenario(episode_seed), None, profile=self.profile,
                             sensing="inline", stack=self._make_agent)
        self._accel, self._over = 0.0, False
        self._going = self.runner.start() and self.runner.advance()
        return self._observe(), self._info()

    def step(self, action: NDArray[np.float32]
             ) -> tuple[Observation, SupportsFloat, bool, bool, dict[str, Any]]:
        runner, agent = self.runner, self.agent
        if runner is None or agent is None or self._over:
            raise RuntimeError("step() before reset() or after the episode ended")
        a = np.clip(np.asarray(action, np.float64), self.actions.low, self.actions.high)
        agent.action = Action(float(a[0]), float(a[1]))
        t0, s0 = runner.world.t, runner.world.ego_route.station  # [s], [m]
        for _ in range(self.action_repeat):
            if not self._going or runner.failed_so_far:
                break
            self._going = runner.advance()
        terminated = runner.failed_so_far or runner.error is not None
        self._over = terminated or not self._going
        outcome = StepOutcome(progress=runner.world.ego_route.station - s0,
                              lane_error=self._lane_error(), dt=runner.world.t - t0,
                              accel_change=agent.action.accel - self._accel,
                              failed=terminated)
        self._accel = agent.action.accel
        observation, info = self._observe(), self._info()
        if self._over:
            info |= self._final()
        return observation, reward(outcome), terminated, self._over and not terminated, info

    def render(self) -> NDArray[np.uint8] | None:
        front = self.agent.latest.get("front") if self.agent is not None else None
        return np.asarray(front.rgb, np.uint8) if isinstance(front, CameraFrame) else None

    def close(self) -> None:
        self._end_run()
        super().close()

    # -- the run --------------------------------------------------------------------------------

    def _make_agent(self, ctx: StackContext) -> AgentStack:
        self.agent = AgentStack(ctx)
        return self.agent

    def _lane_error(self) -> float:
        """[m] the car's true offset from its lane's centre at the last control tick (0
        before the first)."""
        assert self.runner is not None
        column = self.runner.log.lane_error
        return float(column[-1]) if len(column) else 0.0

    def _observe(self) -> Observation:
        assert self.runner is not None and self.agent is not None
        if self.observation == "sensors":
            return self._sensors.encode(self.agent.latest)
        return self._truth.encode(self.runner.world, self._lane_error())

    def _info(self) -> dict[str, Any]:
        runner = self.runner
        assert runner is not None
        return {"t": runner.world.t, "privileged": self.observation == "truth",
                "failed": [c.name for c in runner.criteria.items
                           if c.first_failure is not None],
                "collisions": runner.collisions.count}

    def _final(self) -> dict[str, Any]:
        """Finish the run: its verdict and error line (None: none) for the info dict."""
        assert self.runner is not None
        result = self.runner.finish()
        return {"verdict": result.verdict.value,
                "error": result.error.line() if result.error is not None else None}

    def _end_run(self) -> None:
        """Finish the run in hand, if any (its world and files closed)."""
        if self.runner is not None:
            self.runner.finish()
        self.runner, self._over = None, True
