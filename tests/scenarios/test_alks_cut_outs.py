"""ALKS (UN R157) 4.5.x cut-outs: a lead changes lanes away 50 m before a pedestrian (and a
bus) standing in the ego's lane; the ego stops short of them.

Each test runs twice (`tests.scenarios.modes`): `[truth]`, the bundled planner and control on
the privileged ground truth (profile `none`), in `make test`; `[sensors]`, the whole stack on
the `default` profile's cameras and LiDAR, in `make acceptance`."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from avsim.run.runner import RunResult
from tests.scenarios import alks

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def runs(run_scenario: Callable[..., RunResult], mode: str) -> dict[str, RunResult]:
    return {n: alks.run(run_scenario, n, stack=mode) for n in ("4_5_1", "4_5_2")}


@pytest.mark.parametrize("number", ["4_5_1", "4_5_2"])
def test_the_lead_cuts_out_and_the_ego_stops_for_the_target(runs: dict[str, RunResult],
                                                            number: str) -> None:
    result = runs[number]
    assert alks.ended_by_stop_trigger(result)
    _, lead = alks.actor(result, "LeadVehicle")
    assert alks.in_ego_lane(lead[:1]).all() and not alks.in_ego_lane(lead[-1:]).any()
    assert 0.0 < alks.stopped_short(result, "TargetBlocking") < 30.0
    assert not alks.failed(result), alks.failed(result)
