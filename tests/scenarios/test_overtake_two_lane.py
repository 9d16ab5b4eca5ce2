"""A pass through the oncoming lane on a road with one lane each way (30 km/h, a broken
centre line): a van stands in the ego's lane; the oncoming car comes past first while the
ego waits behind the van (the reason logged); then the ego passes through the oncoming lane
and returns to its own lane once the van is behind.

Each test runs twice (`tests.scenarios.modes`): `[truth]`, the bundled planner and control on
the privileged ground truth (profile `none`), in `make test`; `[sensors]`, the whole stack on
the `default` profile's cameras and LiDAR, in `make acceptance`. Each run has its own
golden file (`overtake_two_lane.truth`, `overtake_two_lane`)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from avsim.run.runner import RunResult
from tests.scenarios import golden

pytestmark = pytest.mark.slow
LANE_WIDTH = 3.5  # [m] the scenario's; the road runs along +x from the origin: y is the
#   true offset from lane 0's centre, the oncoming lane's centre at y = 3.5 m


@pytest.fixture(scope="module")
def result(run_scenario: Callable[..., RunResult], mode: str) -> RunResult:
    return run_scenario("overtake_two_lane", record=False, stack=mode)


def _actor(result: RunResult, name: str) -> tuple[np.ndarray, np.ndarray]:
    k = [a.id for a in result.scenario.world.actors].index(name)
    log = result.log
    return np.array(log.actor_station)[:, k], np.array(log.actor_offset)[:, k]


def test_the_ego_waited_for_the_oncoming_car_then_passed_the_van(result: RunResult) -> None:
    log = result.log
    t, x, y = log.array("t"), log.array("x"), log.array("y")
    van_s, _ = _actor(result, "van")
    car_s, car_offset = _actor(result, "oncoming")
    assert np.ptp(van_s) < 0.01  # the van stood
    assert np.abs(car_offset - LANE_WIDTH).max() < 0.1  # the car kept the oncoming lane
    motion = [(c.t, c.source, c.target, c.reason) for c in result.state_changes
              if c.machine == "motion"]
    waits = [m for m in motion if m[1] == m[2] == "lane_keep"]
    assert waits and waits[0][3].startswith("no pass: oncoming car ")
    out = next(m for m in motion if m[2] == "lane_change_left")
    assert out[3] == "a slower vehicle ahead, a pass through the oncoming lane is safe"
    i_out = int(np.searchsorted(t, out[0]))
    # the oncoming car came past the ego while it waited behind the van, in its own lane
    assert car_s[i_out] < x[i_out]
    met = int(np.argmax(car_s < x))
    assert np.abs(y[:met + 1]).max() < 0.5 and x[met] < van_s[0]
    # then in the oncoming lane alongside the van, and back into its own lane past it
    inside = np.abs(y - LANE_WIDTH) < 0.5
    assert inside.any()
    alongside = inside & (np.abs(x - van_s) < 3.0)
    assert alongside.any()
    back = int(np.nonzero(inside)[0][-1])
    assert x[back] > van_s[0] + 5.0  # left the oncoming lane only past the van
    assert abs(y[-1]) < 0.3 and x[-1] > van_s[0] + 30.0
    assert [m[1:3] for m in motion if m[1] != m[2]] == [
        ("lane_keep", "lane_change_left"), ("lane_change_left", "lane_keep"),
        ("lane_keep", "lane_change_right"), ("lane_change_right", "lane_keep")]
    # the stack kept lane -1 for the pass only, no longer than needed
    lanes = np.array(log.lane)
    assert set(lanes.tolist()) == {0, -1} and lanes[-1] == 0
    assert (t[lanes == -1][-1] - t[lanes == -1][0]) < 8.0


def test_no_track_was_ever_in_the_way(result: RunResult) -> None:
    """The pass started with the oncoming lane clear: no emergency brake, no abort."""
    assert not any("abort" in c.reason for c in result.state_changes)
    assert "emergency" not in [c.target for c in result.state_changes]
    assert "emergency" not in {s.value for s in result.log.speed_source}


def test_verdicts(result: RunResult) -> None:
    c = {r.name: r for r in result.criteria}
    assert not any(r.failed for r in result.criteria), result.criteria
    assert c["no_collision"].passed and c["completes"].passed
    # in lane -1 and back judged as lane changes: inside a lane's lines all along
    value = c["tyres_in_lane"].value
    assert c["tyres_in_lane"].passed and value is not None and value > 0.0
    assert result.sim_time is not None and result.sim_time < 40.0


def test_result_matches_golden(result: RunResult, mode: str) -> None:
    golden.check(result, golden.label("overtake_two_lane", mode))
