"""ICCAS lane changing: a car 30 km/h slower ahead, the left lane free; the ego changes lanes
left to pass it (the motion FSM's decision from the tracks), without contact, taking under
5 s from leaving its lane to being inside the target lane, at no more than 1 m/s^2 of lateral
acceleration; once the passed car is 2 s behind it keeps right (issue K, item 7), and ends
with every tyre inside its lane.

Each test runs twice (`tests.scenarios.modes`): `[truth]`, the bundled planner and control on
the privileged ground truth (profile `none`), in `make test`; `[sensors]`, the whole stack on
the `default` profile's cameras and LiDAR, in `make acceptance`. The camera's lane is judged
on the sensor run only. Each run has its own golden file (`lane_change.truth`,
`lane_change`)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from avsim.run.runner import RunResult
from tests.scenarios import golden
from tests.scenarios.modes import SENSORS

pytestmark = pytest.mark.slow
KPH = 1 / 3.6


@pytest.fixture(scope="module")
def result(run_scenario: Callable[..., RunResult], mode: str) -> RunResult:
    return run_scenario("lane_change", record=False, stack=mode)


def test_the_ego_overtook_the_slower_car(result: RunResult) -> None:
    log = result.log
    t, s, v = log.array("t"), log.array("station"), log.array("speed")
    k = [a.id for a in result.scenario.world.actors].index("slow")
    slow_s = np.array(log.actor_station)[:, k]
    slow_offset = np.array(log.actor_offset)[:, k]
    assert np.abs(slow_offset).max() < 0.1  # it kept the ego's lane 0 throughout
    rel = v - np.gradient(slow_s, t)
    assert rel[0] == pytest.approx(30 * KPH, abs=0.5 * KPH)  # 30 km/h slower
    change = next(c for c in result.state_changes if c.machine == "motion")
    i = int(np.searchsorted(t, change.t))
    assert rel[i] > 20 * KPH  # still closing fast when it pulled out (the ACC trailed 1 s)
    assert 10.0 < slow_s[i] - s[i] < 100.0  # it was ahead when the change began
    assert s[-1] > slow_s[-1] + 30.0  # and is behind now
    assert log.lane[0] == 0 and max(log.lane) == 1 and log.lane[-1] == 0  # passed, kept right


def test_the_motion_fsm_changed_left_to_pass_then_kept_right(result: RunResult) -> None:
    motion = [(c.source, c.target, c.reason) for c in result.state_changes
              if c.machine == "motion"]
    assert [m[:2] for m in motion] == [("lane_keep", "lane_change_left"),
                                       ("lane_change_left", "lane_keep"),
                                       ("lane_keep", "lane_change_right"),
                                       ("lane_change_right", "lane_keep")]
    assert "slower vehicle" in motion[0][2] and "keep right" in motion[2][2]
    acc = [c.target for c in result.state_changes if c.machine == "acc"]
    # slowed behind it; from the moment the pass begins it is no lead: the path clears it
    # (issue K, item 6: the pass does not trail the car it leaves)
    assert acc == ["cruise", "trail", "cruise"]
    assert result.metrics["acc_shortest_mode"] >= 0.5


def test_verdict_and_the_lane_change_figures(result: RunResult, mode: str) -> None:
    assert not any(c.failed for c in result.criteria), result.criteria
    c = {r.name: r for r in result.criteria}
    assert 0.5 < c["lane_change_duration"].value < 5.0
    assert 0.2 < c["lane_change_lateral_accel"].value <= 1.0
    assert c["tyres_in_lane"].value > 0.0  # in the target lane after, in the two during
    # settled back in lane 0: the cross-track error is small
    assert abs(result.log.cross_track[-1]) < 0.15
    if mode != SENSORS:
        return  # no camera on the truth: the lane is the map's
    # the camera's lane moved with the car: off by a lane width only in the frames while
    # the car's centre is between the line and the 0.2 m re-assignment margin, at each of
    # the two crossings (0.4 m for one: the squared error doubles with two)
    assert result.metrics["lane_offset_rmse"] < 0.4 * np.sqrt(2.0)
    sources = [c.target for c in result.state_changes if c.machine == "lane_source"]
    assert sources == ["camera"]


def test_result_matches_golden(result: RunResult, mode: str) -> None:
    golden.check(result, golden.label("lane_change", mode))
