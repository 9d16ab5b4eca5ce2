"""Lateral moves that yield (issue K, items 3 and 4), from the acceptance set:

- `pass_stopped_car`: a lead cuts out and reveals a car stopped in the ego's lane while five
  cars come up from behind in the left lane; the ego (overtaking on) stops behind the stopped
  car with room to pull out, lets them all pass, then changes lanes from the standstill,
  passes it and keeps right, without contact;
- `flat_tyre_traffic`: a flat tyre in the left lane with a faster car approaching from behind
  in the right lane; the ego slows in its lane with the hazard lights on until that car has
  passed, then moves right and onto the shoulder and stops there, without contact.

Each test asserts its situation from the truth (the actors' stations and offsets) as well
as the verdicts."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from numpy.typing import NDArray

from avsim.run.runner import RunResult
from world.actors.catalogue import CATALOGUE, DEFAULT_MODEL
from world.hdmap import SHOULDER
from world.sensors.setup import Profile

pytestmark = [pytest.mark.slow, pytest.mark.acceptance]  # the acceptance set: `make acceptance`
CAR = CATALOGUE[DEFAULT_MODEL["car"]].length  # [m] a `type: car` actor's body
EGO = 4.8  # [m] the ego's body
W = 3.5  # [m] lane width of both scenarios
KPH = 1 / 3.6
PASS = "scenarios/acceptance/pass_stopped_car.yaml"
FLAT = "scenarios/acceptance/flat_tyre_traffic.yaml"


@pytest.fixture(scope="module")
def passing(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run_scenario(PASS, record=False, profile=Profile.FAST)


@pytest.fixture(scope="module")
def flat(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run_scenario(FLAT, record=False, profile=Profile.FAST)


def _actor(result: RunResult, name: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(station, offset) [m] of actor `name` per tick, from the truth."""
    k = [a.id for a in result.scenario.world.actors].index(name)
    return (np.array(result.log.actor_station)[:, k], np.array(result.log.actor_offset)[:, k])


def _first_change(result: RunResult, machine: str, target: str) -> float:
    return next(c.t for c in result.state_changes
                if c.machine == machine and c.target == target)


# -- passing a stopped car -----------------------------------------------------------------


def test_a_cut_out_revealed_a_car_stopped_in_the_egos_lane(passing: RunResult) -> None:
    t, s = passing.log.array("t"), passing.log.array("station")
    stopped_s, stopped_d = _actor(passing, "stopped")
    assert np.ptp(stopped_s) < 0.01 and np.abs(stopped_d).max() < 0.1  # stood in lane 0
    lead_s, lead_d = _actor(passing, "lead")
    assert abs(lead_d[0]) < 0.1 and lead_d[-1] == pytest.approx(W, abs=0.1)  # cut out left
    out = int(np.argmax(lead_d > W - 0.2))
    assert lead_s[out] < stopped_s[0] - CAR  # it left the lane before the stopped car
    assert stopped_s[0] - s[out] < 100.0  # revealed to the ego within 100 m
    assert t[out] < _first_change(passing, "motion", "lane_change_left")


def test_the_ego_stood_behind_it_with_room_while_the_rear_cars_passed(
        passing: RunResult) -> None:
    t, s, v = (passing.log.array(k) for k in ("t", "station", "speed"))
    t_change = _first_change(passing, "motion", "lane_change_left")
    i = int(np.searchsorted(t, t_change))
    stopped_s, _ = _actor(passing, "stopped")
    standing = (v < 0.1) & (t < t_change)
    assert t[standing][-1] - t[standing][0] > 2.0  # a standstill of seconds before the pass
    gap = stopped_s[0] - s[standing] - (CAR + EGO) / 2
    assert gap.min() > 8.0 and gap.max() < 15.0  # room to pull out (R157's 2-6 m is not)
    for k in range(1, 6):
        rear_s, rear_d = _actor(passing, f"rear_{k}")
        assert np.abs(rear_d - W).max() < 0.1  # in the left lane throughout
        assert rear_s[0] < s[0] - EGO  # behind the ego at the start
        assert np.gradient(rear_s, t)[0] > v[0] + 2.0  # and faster
        assert rear_s[i] - CAR / 2 > s[i] + EGO / 2  # past the ego when it pulled out


def test_the_ego_passed_the_stopped_car_and_kept_right(passing: RunResult) -> None:
    s = passing.log.array("station")
    stopped_s, _ = _actor(passing, "stopped")
    motion = [(c.source, c.target) for c in passing.state_changes if c.machine == "motion"]
    assert motion == [("lane_keep", "lane_change_left"), ("lane_change_left", "lane_keep"),
                      ("lane_keep", "lane_change_right"), ("lane_change_right", "lane_keep")]
    assert s[-1] > stopped_s[0] + 30.0
    assert passing.log.lane[-1] == 0


def test_passing_verdicts(passing: RunResult) -> None:
    assert not any(c.failed for c in passing.criteria), passing.criteria
    c = {r.name: r for r in passing.criteria}
    assert c["no_collision"].value == 0
    assert c["tyres_in_lane"].passed and c["completes"].passed


# -- a flat tyre with traffic in the target lane ----------------------------------------------


def test_a_faster_car_came_up_behind_in_the_right_lane_at_the_flat(flat: RunResult) -> None:
    t, s, v = (flat.log.array(k) for k in ("t", "station", "speed"))
    rear_s, rear_d = _actor(flat, "rear")
    assert np.abs(rear_d).max() < 0.1  # in lane 0 (the right lane) throughout
    assert flat.log.lane[0] == 1  # the ego in the left lane
    i = int(np.searchsorted(t, _first_change(flat, "hazard", "on")))
    gap = s[i] - rear_s[i] - (CAR + EGO) / 2
    assert 15.0 < gap < 40.0  # behind, near
    assert np.gradient(rear_s, t)[i] > v[i]  # and approaching


def test_the_ego_waited_with_hazards_on_until_it_passed_then_pulled_over(
        flat: RunResult) -> None:
    t, s, v = (flat.log.array(k) for k in ("t", "station", "speed"))
    rear_s, _ = _actor(flat, "rear")
    t_flat = _first_change(flat, "hazard", "on")
    t_move = _first_change(flat, "motion", "lane_change_right")
    assert t_move - t_flat > 2.0  # it waited in its lane
    i, j = int(np.searchsorted(t, t_flat)), int(np.searchsorted(t, t_move))
    assert all(flat.log.hazard[i:j]) and all(lane == 1 for lane in flat.log.lane[i:j - 1])
    assert v[j] < v[i] - 5.0  # slowing meanwhile
    assert rear_s[j] - CAR / 2 > s[j] + EGO / 2  # the rear car had passed
    lanes = [lane for k, lane in enumerate(flat.log.lane) if k >= j]
    assert lanes[-1] == SHOULDER and v[-1] < 0.1 and flat.log.hazard[-1]


def test_flat_tyre_verdicts(flat: RunResult) -> None:
    assert not any(c.failed for c in flat.criteria), flat.criteria
    c = {r.name: r for r in flat.criteria}
    assert c["no_collision"].value == 0 and c["tyres_in_lane"].passed
    assert c["completes"].passed and "minimum-risk" in (c["completes"].note or "")
    assert c["minimum_risk_stop"].passed
