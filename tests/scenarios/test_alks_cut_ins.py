"""ALKS (UN R157) scenarios with a vehicle coming in or beside: 4.4.x cut-ins (avoidable and
unavoidable under 5.2.5.2), 4.6.x detection ranges."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from avsim.criteria.base import Verdict
from avsim.run.runner import RunResult
from tests.scenarios import alks

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def runs(run_scenario: Callable[..., RunResult]) -> dict[str, RunResult]:
    return {n: alks.run(run_scenario, n) for n in ("4_4_1", "4_4_2", "4_6_1", "4_6_2")}


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
    ("4_6_2", "SideVehicle"),
])
def test_the_detection_range_is_reported(runs: dict[str, RunResult], number: str,
                                         entity: str) -> None:
    result = runs[number]
    assert alks.ended_by_stop_trigger(result)
    distance = result.metrics[f"first_tracked_distance_{entity.lower()}"]
    assert 0.0 < distance < 100.0  # tracked, within the LiDAR's 100 m
    assert not alks.failed(result), alks.failed(result)


def test_the_motorbike_beside_is_detected_as_a_motorcycle(runs: dict[str, RunResult]) -> None:
    """Its 2.2 m side beside the car is boxed as a motorcycle's where it is (a truck's rear
    grown 6.7 m away before the class existed: never matched, never tracked)."""
    metrics = runs["4_6_2"].metrics
    assert metrics["detection_precision_motorcycle"] == 1.0  # called so, and on it
    assert metrics["detection_recall_motorbike"] > 0.9
    assert metrics["track_recall_motorbike"] > 0.9
