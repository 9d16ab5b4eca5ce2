"""ALKS (UN R157) 4.2.x blocking targets and 4.5.x cut-outs revealing them: a pedestrian (and
a bus) standing in the ego's lane 500 m ahead, or crossing it, or behind a lead that changes
lanes away at the last moment. The ego stops short of them, unless the target crosses into
its lane too close for its LiDAR to see in time.

Each test runs twice (`tests.scenarios.modes`): `[truth]`, the bundled planner and control on
the privileged ground truth (profile `none`), in `make test`; `[sensors]`, the whole stack on
the `default` profile's cameras and LiDAR, in `make acceptance`. The LiDAR's
tracking range of the crossing walker is judged on the sensor run only."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from avsim.run.runner import RunResult
from tests.scenarios import alks
from tests.scenarios.modes import SENSORS

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def runs(run_scenario: Callable[..., RunResult], mode: str) -> dict[str, RunResult]:
    return {n: alks.run(run_scenario, n, stack=mode) for n in ("4_2_1", "4_2_2", "4_2_3", "4_2_4")}


@pytest.mark.parametrize("number", ["4_2_1", "4_2_2", "4_2_4"])
def test_the_ego_stops_for_a_target_in_its_lane(runs: dict[str, RunResult],
                                               number: str) -> None:
    result = runs[number]
    assert alks.ended_by_stop_trigger(result)
    s, offset = alks.actor(result, "TargetBlocking")
    assert np.all(alks.in_ego_lane(offset)) and np.ptp(s) == 0.0  # standing in the lane
    assert 0.0 < alks.stopped_short(result, "TargetBlocking") < 30.0
    assert not alks.failed(result), alks.failed(result)


def test_a_partially_blocking_target_is_half_in_the_lane(runs: dict[str, RunResult]) -> None:
    _, offset = alks.actor(runs["4_2_2"], "TargetBlocking")
    assert offset[0] == pytest.approx(alks.EGO_LANE * alks.LANE_WIDTH - 1.5)


def test_the_bus_stands_behind_the_pedestrian(runs: dict[str, RunResult]) -> None:
    result = runs["4_2_4"]
    (bus,) = [a for a in result.scenario.world.actors if a.id == "targetblocking2"]
    assert bus.model is not None and bus.model.length == 13.5
    s_bus, offset = alks.actor(result, "TargetBlocking2")
    s_ped, _ = alks.actor(result, "TargetBlocking")
    assert s_bus[0] > s_ped[0] and np.all(alks.in_ego_lane(offset))


def test_the_pedestrian_crosses_the_ego_lane(runs: dict[str, RunResult]) -> None:
    result = runs["4_2_3"]
    _, offset = alks.actor(result, "TargetBlocking")
    start = alks.fired(result, "CrossAction")
    assert start is not None
    # its reference point 5 m right of the lane centre, its box centre 0.15 m ahead of that
    # (the catalog's), facing across the road (heading 1.57 rad)
    assert offset[0] == pytest.approx(alks.EGO_LANE * alks.LANE_WIDTH - 5.0 + 0.15, abs=1e-3)
    assert alks.in_ego_lane(offset).any()  # it walked into the lane


def test_the_ego_does_not_hit_the_crossing_pedestrian(runs: dict[str, RunResult],
                                                      mode: str) -> None:
    """One LiDAR ring crosses the walker beyond 30 m, on two or three columns: it is tracked
    as a pedestrian from about 55 m, on the road's edge, and its walk is seen to cross the
    car's path: the car slows for it before it steps into the lane, and drives on after.
    On the truth (a track from the start) the tracking range is not judged."""
    result = runs["4_2_3"]
    if mode == SENSORS:
        assert result.metrics["first_tracked_distance_targetblocking"] > 45.0
    assert not alks.failed(result), alks.failed(result)
    s, offset = alks.actor(result, "TargetBlocking")
    ahead = s - result.log.array("station")
    inside = alks.in_ego_lane(offset) & (ahead > 0.0)
    assert inside.any()  # it was in the lane ahead of the car
    assert result.log.array("speed")[inside].min() < 8.0  # the car slowed for it
