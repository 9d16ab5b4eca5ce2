"""LiDAR tracking in the loop: eight vehicles in five lanes, one overtaking the ego; the
scores come from the result JSON, as a user would read them."""

from __future__ import annotations

import json
from collections.abc import Callable

import numpy as np
import pytest

from avsim.run.result import result_json
from avsim.run.runner import RunResult
from perception.objects import DetectorParams
from tests.scenarios import golden
from world.actors.catalogue import CATALOGUE, DEFAULT_MODEL

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def result(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run_scenario("tracking", record=False)


def test_the_situation_happened(result: RunResult) -> None:
    """>= 5 cars in several lanes at several speeds; the overtaker came from behind and
    passed the ego; the ego passed the slower cars on its right."""
    spec = result.scenario.world
    cars = [a for a in spec.actors if a.type.value in ("car", "truck")]
    assert len(cars) >= 5
    assert len({a.lane for a in cars}) >= 4 and len({a.speed for a in cars}) >= 5
    ids = [a.id for a in spec.actors]
    ego = result.log.array("station")
    actors = np.array(result.log.actor_station)
    ahead = actors - ego[:, None]  # > 0: the actor is ahead of the ego
    overtaker = ids.index("overtaker")
    assert ahead[0, overtaker] < -10.0 and ahead[-1, overtaker] > 30.0
    for slower in ("slow_right", "far_right", "truck"):
        k = ids.index(slower)
        assert ahead[0, k] > 0.0 and ahead[-1, k] < -10.0, slower


def test_tracking_scores_from_the_result_json(result: RunResult) -> None:
    payload = json.loads(json.dumps(result_json(result, "tracking", "none.rrd", "default")))
    m = payload["metrics"]
    assert payload["passed"], payload["criteria"]
    assert m["track_recall"] >= 0.95  # visible cars within 50 m
    assert m["detection_recall"] >= 0.95 and m["detection_precision"] >= 0.95
    # the truck, seen from behind and ahead with its far end unseen, gets the detector's
    # generic truck length: its box centre is off by half the difference there
    truck, prior = CATALOGUE[DEFAULT_MODEL["truck"]], DetectorParams().truck
    assert m["track_position_rmse_truck"] <= 0.5 * (truck.length - prior.length)
    assert m["track_speed_rmse"] <= 0.5
    assert m["lane_offset_rmse"] <= 0.10  # the camera's lane held with traffic alongside


@pytest.mark.xfail(strict=True, reason=(
    "known limit: 0.332 m. Beyond about 27 m only the -1 deg ring reaches a car, above a "
    "saloon's boot deck (its rear screen, 0.85 m before the bumper) or at a bonnet seen from "
    "ahead: the box is grown from that set-back face; the tracker then coasts along the car "
    "on its velocity (1-sigma ~0.5 m/s), which drifts over the 2 to 4 s a car spends in the "
    "one-ring band (0.121 m on box bodies, 0.465 m on shapes before the lower-body fit)"))
def test_car_tracks_are_within_0_3_m(result: RunResult) -> None:
    assert _metrics(result)["track_position_rmse_car"] <= 0.3


@pytest.mark.xfail(strict=True, reason=(
    "known limit: 2 per car per 100 s. Where the ring leaves a saloon's boot deck its "
    "returns split into fragments and the track of that car is dropped and started again "
    "(box bodies: at most 1)"))
def test_a_car_keeps_its_track(result: RunResult) -> None:
    assert _metrics(result)["max_id_switches_per_car_per_100s"] <= 1.0


def _metrics(result: RunResult) -> dict[str, float]:
    """The run's metrics as its result JSON gives them."""
    payload = json.loads(json.dumps(result_json(result, "tracking", "none.rrd", "default")))
    out: dict[str, float] = payload["metrics"]
    return out


def test_result_matches_golden(result: RunResult) -> None:
    golden.check(result, "tracking")
