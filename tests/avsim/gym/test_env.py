"""`avsim.gym`: the environment passes Gymnasium's checker (truth and sensor observations),
runs in Gymnasium's vector API over two scenarios, is deterministic for a seed, ends an
episode as terminated on a contact and as truncated at the scenario's end, and a random
agent runs an episode on each of three scenarios (bundled, and a campaign family)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import SyncVectorEnv

from avsim.gym import ENV_ID, AvsimEnv
from avsim.gym.agent import AgentStack
from avsim.gym.reward import FAIL_PENALTY

STRAIGHT = """\
format: avsim/1
name: straight
duration: 1
road:
  speed_limit_kph: 50
  segments:
    - straight: 300
ego: {s: 10, speed_kph: 30, set_speed_kph: 30}
"""

STOPPED_CAR = """\
format: avsim/1
name: stopped_car
duration: 6
road:
  speed_limit_kph: 70
  segments:
    - straight: 300
ego: {s: 10, speed_kph: 40, set_speed_kph: 40}
actors:
  - {id: stopped, type: car, lane: 0, s: 45, speed_kph: 0}
"""


def _file(tmp_path: Path, text: str, name: str) -> str:
    path = tmp_path / f"{name}.yaml"
    path.write_text(text, encoding="utf-8")
    return str(path)


@pytest.fixture
def straight(tmp_path: Path) -> str:
    return _file(tmp_path, STRAIGHT, "straight")


def _episode(env: gymnasium.Env[Any, Any], seed: int, action: Any = None
             ) -> tuple[list[Any], list[float], bool, bool, dict[str, Any]]:
    """One episode (a random agent from `seed` unless `action` is given): the observations,
    rewards, the last terminated and truncated flags and info."""
    obs, info = env.reset(seed=seed)
    env.action_space.seed(seed)
    observations, rewards = [obs], []
    terminated = truncated = False
    while not (terminated or truncated):
        a = env.action_space.sample() if action is None else action
        obs, r, terminated, truncated, info = env.step(a)
        observations.append(obs)
        rewards.append(float(r))
    return observations, rewards, terminated, truncated, info


@pytest.mark.parametrize("observation", ["truth", "sensors"])
def test_the_environment_passes_gymnasiums_checker(straight: str, observation: str) -> None:
    env = AvsimEnv(straight, observation=observation, profile="none")
    check_env(env.unwrapped, skip_render_check=True)
    env.close()


def test_it_is_registered_and_made_by_gymnasium(straight: str) -> None:
    env = gymnasium.make(ENV_ID, scenario=straight, observation="truth")
    obs, info = env.reset(seed=1)
    assert env.observation_space.contains(obs) and info["privileged"] is True
    env.close()


def test_the_sensor_observation_holds_gnss_and_odometry_without_cameras(straight: str) -> None:
    env = AvsimEnv(straight, profile="none")
    obs, info = env.reset(seed=2)
    assert set(obs) == {"gnss", "odometry"} and info["privileged"] is False
    assert obs["gnss"][4] == 1.0  # a fix at t = 0
    assert obs["odometry"][:4].mean() * 0.3 == pytest.approx(30 / 3.6, rel=0.1)  # the wheels
    #   of a car at 30 km/h (radius ~0.3 m)
    env.close()


def test_two_scenarios_step_in_a_vector_environment(straight: str, tmp_path: Path) -> None:
    other = _file(tmp_path, STOPPED_CAR, "stopped_car")
    envs = SyncVectorEnv([lambda: AvsimEnv(straight, observation="truth"),
                          lambda: AvsimEnv(other, observation="truth")])
    obs, _ = envs.reset(seed=[1, 2])
    assert obs["actors_mask"].sum(axis=1).tolist() == [0, 1]  # the second has the stopped car
    for _ in range(3):
        obs, rewards, *_ = envs.step(envs.action_space.sample())
        assert rewards.shape == (2,) and np.all(np.isfinite(rewards))
    assert obs["ego"].shape == (2, 7)
    envs.close()


def test_the_same_seed_gives_the_same_episode_bit_for_bit(straight: str) -> None:
    env = AvsimEnv(straight, profile="none")
    first, rewards, *_ = _episode(env, seed=7)
    again, rewards_again, *_ = _episode(env, seed=7)
    other, *_ = _episode(env, seed=8)
    env.close()
    assert len(first) == len(again) and rewards == rewards_again
    for a, b in zip(first, again, strict=True):
        for key in a:
            assert a[key].tobytes() == b[key].tobytes(), key
    assert any(a["gnss"].tobytes() != b["gnss"].tobytes()  # the seed reaches the receiver
               for a, b in zip(first, other, strict=False))


def test_full_throttle_into_a_stopped_car_terminates(tmp_path: Path) -> None:
    env = AvsimEnv(_file(tmp_path, STOPPED_CAR, "stopped_car"), observation="truth")
    _, rewards, terminated, truncated, info = _episode(env, seed=0,
                                                       action=np.array([0.0, 4.0], np.float32))
    env.close()
    assert terminated and not truncated
    assert info["collisions"] >= 1 or info["failed"]
    assert info["t"] < 6.0 and info["verdict"] == "fail"
    assert rewards[-1] < -FAIL_PENALTY / 2  # the terminal penalty, once
    assert all(r > -FAIL_PENALTY / 2 for r in rewards[:-1])


def test_coasting_to_the_scenarios_end_truncates(straight: str) -> None:
    env = AvsimEnv(straight, observation="truth", action_repeat=4)
    _, rewards, terminated, truncated, info = _episode(
        env, seed=0, action=np.array([0.0, 0.0], np.float32))
    env.close()
    assert truncated and not terminated and info["t"] == pytest.approx(1.0)
    assert len(rewards) == 10  # 1 s of 0.1 s steps (4 control periods of 0.025 s)
    assert sum(rewards) == pytest.approx(30 / 3.6 * (1.0 - 0.025), rel=0.05)  # [m] progress
    with pytest.raises(RuntimeError, match="after the episode ended"):
        env.step(np.zeros(2, np.float32))


@pytest.mark.parametrize(("scenario", "overrides"), [
    ("normal_driving", {"duration": 3}),
    ("sudden_stop", {"duration": 3}),
    ("scenarios/campaigns/stationary.yaml", {"duration": 3}),
])
def test_a_random_agent_runs_an_episode(scenario: str, overrides: dict[str, object]) -> None:
    env = AvsimEnv(scenario, overrides=overrides, profile="none", observation="sensors")
    observations, rewards, terminated, truncated, info = _episode(env, seed=11)
    env.close()
    assert terminated or truncated
    assert info["error"] is None and info["verdict"] in ("pass", "fail")
    assert all(env.observation_space.contains(o) for o in observations)
    assert np.all(np.isfinite(rewards)) and 0.0 < info["t"] <= 3.0


def test_a_family_draws_its_episodes_scenario_from_the_seed() -> None:
    env = AvsimEnv("scenarios/campaigns/stationary.yaml", overrides={"duration": 2})
    drawn = [env.source.scenario(seed) for seed in (1, 1, 2)]
    env.close()
    same, again, other = ((s.world.ego.speed, s.world.seed) for s in drawn)
    assert same == again and same != other
    assert all(s.duration == 2.0 for s in drawn)  # the user's override holds


def test_an_error_in_the_run_ends_the_episode_with_its_line(
        straight: str, monkeypatch: pytest.MonkeyPatch) -> None:
    ticks = AgentStack.tick

    def tick(self: AgentStack, t: float, dt: float) -> Any:
        if t > 0.3:
            raise RuntimeError("the wheel fell off")
        return ticks(self, t, dt)

    monkeypatch.setattr(AgentStack, "tick", tick)
    env = AvsimEnv(straight, observation="truth")
    _, rewards, terminated, truncated, info = _episode(env, seed=0,
                                                       action=np.zeros(2, np.float32))
    env.close()
    assert terminated and not truncated and len(rewards) == 4  # at t 0.325 s, in step 4
    assert info["verdict"] == "error" and "the wheel fell off" in info["error"]
    assert rewards[-1] < -FAIL_PENALTY / 2
