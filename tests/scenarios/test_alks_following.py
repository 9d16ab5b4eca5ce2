"""ALKS (UN R157) scenarios following a lead vehicle: 4.1.2 a swerving lead, 4.3.1 a lead
varying its speed, 4.3.2 a lead braking at 9.81 m/s^2.

Each test runs twice (`tests.scenarios.modes`): `[truth]`, the bundled planner and control on
the privileged ground truth (profile `none`), in `make test`; `[sensors]`, the whole stack on
the `default` profile's cameras and LiDAR, in `make acceptance`."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from avsim.run.runner import RunResult
from tests.scenarios import alks

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def runs(run_scenario: Callable[..., RunResult], mode: str) -> dict[str, RunResult]:
    return {n: alks.run(run_scenario, n, stack=mode) for n in ("4_1_2", "4_3_1", "4_3_2")}




def test_the_lead_swerves_within_its_lane_and_the_ego_follows(
        runs: dict[str, RunResult]) -> None:
    result = runs["4_1_2"]
    assert alks.ended_by_stop_trigger(result)
    _, offset = alks.actor(result, "LeadVehicle")
    centre = alks.EGO_LANE * alks.LANE_WIDTH
    assert offset.max() - centre == pytest.approx(1.5, abs=0.05)  # left 1.5 m
    assert offset.min() - centre == pytest.approx(-1.5, abs=0.05)  # right 1.5 m
    assert all(alks.fired(result, f"SwerveAction{k}") is not None for k in ("", 2, 3, 4))
    assert not alks.failed(result), alks.failed(result)
    assert alks.passed(result, "following_gap")


def test_the_lead_speeds_up_and_slows_down_and_the_ego_keeps_d_min(
        runs: dict[str, RunResult]) -> None:
    result = runs["4_3_1"]
    assert alks.ended_by_stop_trigger(result)
    lead = np.array(result.log.lead_speed)
    lead = lead[np.isfinite(lead)]
    # 5 m/s over the ego's speed (60 km/h), then 5 m/s under it: targets taken at the start
    assert lead.max() == pytest.approx(60 * alks.KPH + 5.0, abs=0.3)
    assert lead.min() < 60 * alks.KPH - 4.0
    assert not alks.failed(result), alks.failed(result)
    assert alks.passed(result, "following_gap")


def test_the_lead_brakes_to_a_stop_and_the_ego_stops_behind_it(
        runs: dict[str, RunResult]) -> None:
    result = runs["4_3_2"]
    assert alks.ended_by_stop_trigger(result)
    lead = np.array(result.log.lead_speed)
    assert np.nanmin(lead) < 0.1  # it stopped
    gap = np.array(result.log.lead_gap)
    assert result.log.array("speed")[-1] < 0.1 and 0.0 < gap[-1] < 15.0
    assert not alks.failed(result), alks.failed(result)
