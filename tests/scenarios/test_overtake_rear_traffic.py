"""A fast car coming up behind in the lane a slow ego would pass through
(`scenarios/acceptance/overtake_rear_traffic.yaml`): the ego follows a car
at 20 km/h (overtaking on, set speed 35 km/h) when a car at 65 km/h comes up in the left lane,
in sight and about 40 m back, as the pass is decided. UN R157's rear rule alone (the car
behind brakes at up to 3 m/s^2) lets the ego move out; the car, which does not brake, would
close on it during the slow change. The ego waits, then passes once that car has gone by.

The situation is asserted from the truth (the actors' stations and offsets), then the
verdicts.

Each test runs twice (`tests.scenarios.modes`): `[truth]`, the bundled planner and control on
the privileged ground truth (profile `none`), in `make test`; `[sensors]`, the whole stack on
the `default` profile's cameras and LiDAR, in `make acceptance`."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from numpy.typing import NDArray

from avsim.run.runner import RunResult
from world.actors.catalogue import CATALOGUE, DEFAULT_MODEL

pytestmark = pytest.mark.slow
CAR = CATALOGUE[DEFAULT_MODEL["car"]].length  # [m] a `type: car` actor's body
EGO = 4.8  # [m] the ego's body
W = 3.5  # [m] lane width
KPH = 1 / 3.6
FILE = "scenarios/acceptance/overtake_rear_traffic.yaml"


@pytest.fixture(scope="module")
def result(run_scenario: Callable[..., RunResult], mode: str) -> RunResult:
    return run_scenario(FILE, record=False, stack=mode)


def _actor(result: RunResult, name: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(station, offset) [m] of actor `name` per tick, from the truth."""
    k = [a.id for a in result.scenario.world.actors].index(name)
    log = result.log
    return np.array(log.actor_station)[:, k], np.array(log.actor_offset)[:, k]


def test_the_fast_car_came_up_while_the_ego_wanted_to_pass(result: RunResult) -> None:
    log = result.log
    t, s, y = log.array("t"), log.array("station"), log.array("y")
    slow_s, slow_d = _actor(result, "slow")
    fast_s, fast_d = _actor(result, "fast")
    assert result.scenario.driver.overtake
    assert np.abs(slow_d).max() < 0.1 and np.abs(fast_d - W).max() < 0.1  # kept their lanes
    v_fast = np.gradient(fast_s, t)
    assert np.abs(v_fast - 65 * KPH).max() < 0.2  # 65 km/h throughout, never braking
    # the ego behind the slow car, in its lane, both near 20 km/h
    early = t < 1.5
    assert np.all(slow_s[early] - s[early] > 0.5 * (CAR + EGO))
    assert np.abs(y[early]).max() < 0.3
    assert np.abs(np.gradient(slow_s, t) - 20 * KPH).max() < 0.2
    # the fast car in sight behind in the left lane, closing: 30 to 50 m (bumpers) at 1.3 s,
    # when the pass would have been decided without the rule for a car that does not brake
    i = int(np.searchsorted(t, 1.3))
    gap = s[i] - fast_s[i] - 0.5 * (CAR + EGO)
    assert 30.0 < gap < 50.0


def test_the_ego_passed_only_once_the_fast_car_had_gone_by(result: RunResult) -> None:
    log = result.log
    t, s = log.array("t"), log.array("station")
    slow_s, _ = _actor(result, "slow")
    fast_s, _ = _actor(result, "fast")
    motion = [(c.t, c.source, c.target, c.reason) for c in result.state_changes
              if c.machine == "motion"]
    out = next(m for m in motion if m[2] == "lane_change_left")
    assert out[3] == "a slower vehicle ahead, the left lane free"
    assert not any("abort" in m[3] for m in motion)  # never moved out to come back
    i = int(np.searchsorted(t, out[0]))
    assert fast_s[i] - s[i] > 0.5 * (CAR + EGO)  # the fast car ahead of the ego by then
    lanes = np.array(log.lane)
    assert np.all(lanes[t < out[0]] == 0)
    assert s[-1] > slow_s[-1] + 30.0  # past the slow car
    assert lanes[-1] == 0  # and kept right again
    assert [m[1:3] for m in motion] == [
        ("lane_keep", "lane_change_left"), ("lane_change_left", "lane_keep"),
        ("lane_keep", "lane_change_right"), ("lane_change_right", "lane_keep")]


def test_verdicts(result: RunResult) -> None:
    c = {r.name: r for r in result.criteria}
    assert not any(r.failed for r in result.criteria), result.criteria
    assert c["no_collision"].passed and c["no_collision"].value == 0
    assert c["completes"].passed and c["tyres_in_lane"].passed
    assert result.metrics["collisions"] == 0
