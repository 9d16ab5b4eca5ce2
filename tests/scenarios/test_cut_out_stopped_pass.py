"""A stopped car revealed late by a cut-out, overtaking on (`scenarios/acceptance/
cut_out_stopped_pass.yaml`): the lead, 2 s ahead at 50 km/h, starts its
lane change 30 m short of a car stopped in the ego's lane. The stop that follows is a hard one;
the ego ends it where a pass path clears the stopped car (not at the ACC's d0, from where no
forward path gets around it), passes it through the left lane and keeps right again.

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
FILE = "scenarios/acceptance/cut_out_stopped_pass.yaml"


@pytest.fixture(scope="module")
def result(run_scenario: Callable[..., RunResult], mode: str) -> RunResult:
    return run_scenario(FILE, record=False, stack=mode)


def _actor(result: RunResult, name: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(station, offset) [m] of actor `name` per tick, from the truth."""
    k = [a.id for a in result.scenario.world.actors].index(name)
    return (np.array(result.log.actor_station)[:, k], np.array(result.log.actor_offset)[:, k])


def test_the_lead_cut_out_30_m_before_the_stopped_car(result: RunResult) -> None:
    s, v = result.log.array("station"), result.log.array("speed")
    stopped_s, stopped_d = _actor(result, "stopped")
    assert np.ptp(stopped_s) < 0.01 and np.abs(stopped_d).max() < 0.1  # stood in lane 0
    lead_s, lead_d = _actor(result, "lead")
    headway = (lead_s[0] - s[0] - (CAR + EGO) / 2) / v[0]
    assert headway == pytest.approx(2.0, abs=0.05)
    assert abs(lead_d[0]) < 0.1 and lead_d[-1] == pytest.approx(W, abs=0.1)  # cut out left
    start = int(np.argmax(np.abs(lead_d) > 0.05))  # it starts to move over
    short = stopped_s[0] - CAR / 2 - (lead_s[start] + CAR / 2)
    assert short == pytest.approx(30.0, abs=1.0)


def test_the_ego_passed_the_stopped_car_and_came_back(result: RunResult) -> None:
    s, lane = result.log.array("station"), np.array(result.log.lane)
    stopped_s, _ = _actor(result, "stopped")
    motion = [(c.source, c.target) for c in result.state_changes if c.machine == "motion"]
    assert motion == [("lane_keep", "lane_change_left"), ("lane_change_left", "lane_keep"),
                      ("lane_keep", "lane_change_right"), ("lane_change_right", "lane_keep")]
    alongside = np.abs(s - stopped_s[0]) < (CAR + EGO) / 2
    assert alongside.any() and np.all(lane[alongside] == 1)  # past it in the left lane
    t_change = next(c.t for c in result.state_changes if c.target == "lane_change_left")
    i = int(np.searchsorted(result.log.array("t"), t_change))
    assert stopped_s[0] - s[i] - (CAR + EGO) / 2 > 8.0  # it pulled out well back, not at d0
    assert s[-1] > stopped_s[0] + 30.0 and lane[-1] == 0


def test_verdicts(result: RunResult) -> None:
    assert not any(c.failed for c in result.criteria), result.criteria
    c = {r.name: r for r in result.criteria}
    assert c["no_collision"].value == 0
    assert c["tyres_in_lane"].passed and c["completes"].passed
