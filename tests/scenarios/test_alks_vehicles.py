"""ALKS (UN R157) scenarios with a moving vehicle: 4.1.2 a swerving lead, 4.3.1 a lead
varying its speed, 4.3.2 a lead braking at 9.81 m/s^2, 4.4.x cut-ins (avoidable and
unavoidable under 5.2.5.2), 4.6.x detection ranges."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from avsim.criteria.base import Verdict
from avsim.run.runner import RunResult
from tests.scenarios import alks

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def runs(run_scenario: Callable[..., RunResult]) -> dict[str, RunResult]:
    return {n: alks.run(run_scenario, n)
            for n in ("4_1_2", "4_3_1", "4_3_2", "4_4_1", "4_4_2", "4_6_1", "4_6_2")}


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


@pytest.mark.parametrize("number", ["4_4_1", "4_4_2"])
def test_the_car_cuts_in(runs: dict[str, RunResult], number: str) -> None:
    result = runs[number]
    assert alks.ended_by_stop_trigger(result)
    _, offset = alks.actor(result, "CutInVehicle")
    assert not alks.in_ego_lane(offset[:1]).any() and alks.in_ego_lane(offset[-1:]).all()
    assert alks.fired(result, "CutInAction") is not None


def test_an_avoidable_cut_in_is_avoided(runs: dict[str, RunResult]) -> None:
    result = runs["4_4_1"]
    assert not alks.failed(result), alks.failed(result)
    assert alks.passed(result, "no_collision")


def test_a_cut_in_r157_calls_unavoidable_is_not_failed(runs: dict[str, RunResult]) -> None:
    """10 m ahead at 3 m/s across: TTC at the lane intrusion under 20 km/h / 12 m/s^2 +
    0.35 s; a collision, if any, is reported (not applicable), never failed."""
    result = runs["4_4_2"]
    assert not alks.failed(result), alks.failed(result)
    collision = alks.verdicts(result)["no_collision"]
    assert collision.verdict in (Verdict.PASS, Verdict.NOT_APPLICABLE)
    if collision.verdict is Verdict.NOT_APPLICABLE:
        assert "unavoidable under UN R157 5.2.5.2" in (collision.note or "")


@pytest.mark.parametrize(("number", "entity"), [
    ("4_6_1", "TargetBlocking"),
    pytest.param("4_6_2", "SideVehicle", marks=pytest.mark.xfail(
        strict=True, reason="the detector has no motorbike class: the 2.2 m side of the "
        "motorbike beside the ego is boxed as a truck's rear and grown 6.7 m away from the "
        "sensor, its centre 2.9 m off: never matched, so never tracked (issue K)")),
])
def test_the_detection_range_is_reported(runs: dict[str, RunResult], number: str,
                                         entity: str) -> None:
    result = runs[number]
    assert alks.ended_by_stop_trigger(result)
    distance = result.metrics[f"first_tracked_distance_{entity.lower()}"]
    assert 0.0 < distance < 100.0  # tracked, within the LiDAR's 100 m
    assert not alks.failed(result), alks.failed(result)
