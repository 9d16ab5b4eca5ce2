"""ICCAS external disturbance: the driver holds the accelerator fully down for 5 s. The
drive-by-wire stack lets the car speed up to the posted limit and no further (limit + 1 km/h),
keeps it in its lane; following a lead, lets it close up but never below UN R157's d_min.

Each test runs twice (`tests.scenarios.modes`): `[truth]`, the bundled planner and control on
the privileged ground truth (profile `none`), in `make test`; `[sensors]`, the whole stack on
the `default` profile's cameras and LiDAR, in `make acceptance`.
Each run has its own golden file (`NAME.truth`, `NAME`)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from avsim.run.runner import RunResult
from planner.fsm.acc import AccParams, gaps
from tests.scenarios import golden
from world.actors.catalogue import CATALOGUE, DEFAULT_MODEL

NPC_CAR_LENGTH = CATALOGUE[DEFAULT_MODEL["car"]].length  # [m] a `type: car` actor's body

pytestmark = pytest.mark.slow
KPH = 1 / 3.6


@pytest.fixture(scope="module")
def alone(run_scenario: Callable[..., RunResult], mode: str) -> RunResult:
    return run_scenario("external_disturbance", record=False, stack=mode)


@pytest.fixture(scope="module")
def following(run_scenario: Callable[..., RunResult], mode: str) -> RunResult:
    return run_scenario("external_disturbance_following", record=False, stack=mode)


def _pressed(r: RunResult) -> np.ndarray:
    pedal = r.log.array("pedal")
    assert pedal.max() == 1.0
    return pedal > 0.5


def test_the_pedal_raised_the_speed_to_the_limit_and_no_further(alone: RunResult) -> None:
    assert not any(c.failed for c in alone.criteria), alone.criteria
    t, v = alone.log.array("t"), alone.log.array("speed")
    pressed = _pressed(alone)
    held = t[pressed]
    assert held[-1] - held[0] == pytest.approx(5.0, abs=0.05)  # pressed 5 s
    before = v[t < held[0]][-1]
    assert before == pytest.approx(30 * KPH, abs=0.5 * KPH)  # at the set speed
    assert v[pressed].max() >= 39 * KPH  # the pedal did speed it up to the limit ...
    assert v.max() <= 41 * KPH  # ... and no further (the speed_limit criterion too)
    assert v[-1] == pytest.approx(30 * KPH, abs=0.5 * KPH)  # back to the set speed after
    c = {r.name: r for r in alone.criteria}
    assert c["speed_limit"].value <= 1.0 and c["tyres_in_lane"].value > 0.0


def test_following_the_pedal_closes_up_but_never_below_d_min(following: RunResult) -> None:
    assert not any(c.failed for c in following.criteria), following.criteria
    log = following.log
    v = log.array("speed")
    k = [a.id for a in following.scenario.world.actors].index("lead")
    gap = np.array(log.actor_station)[:, k] - log.array("station") - (NPC_CAR_LENGTH + 4.8) / 2
    pressed = _pressed(following)
    start = int(np.argmax(pressed))
    d_des = gaps(v[start], v[start], AccParams()).d_des
    assert gap[start] == pytest.approx(d_des, abs=2.0)  # it was following at d_des
    # the pedal closed it up (towards d_min + 2 m, at the trail law's 4 s time constant) ...
    assert gap[pressed].min() < gap[start] - 1.5
    lead_v = np.gradient(np.array(log.actor_station)[:, k], log.array("t"))
    assert (v[pressed] - lead_v[pressed]).max() > 0.3
    c = {r.name: r for r in following.criteria}
    assert c["min_gap"].value >= c["min_gap"].threshold  # ... never below d_min
    assert v.max() <= 50 * KPH + 1 * KPH
    assert gap[-1] == pytest.approx(gaps(v[-1], v[-1], AccParams()).d_des, abs=2.0)  # after


def test_results_match_golden(alone: RunResult, following: RunResult, mode: str) -> None:
    golden.check(alone, golden.label("external_disturbance", mode))
    golden.check(following, golden.label("external_disturbance_following", mode))
