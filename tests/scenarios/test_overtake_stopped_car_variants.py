"""The overtake family's failing points (`scenarios/acceptance/overtake_stopped_car_variants.yaml`,
`fast` profile): a car stands in the ego's lane while a faster car, which brakes for nobody,
comes up behind in the left lane.

- 000: the car behind at 73 km/h, 67 m back. The ego pulled out in front of it (UN R157's
  rule holds), passed the standing car, then waited `keep_time` (3 s) and `keep_right_gap`
  at its own speed behind the car it had passed before keeping right: the car behind ran
  into it. Now it keeps right as soon as the rear rule lets it (`planner.motion_layer`,
  `yield_behind`), and the car behind goes by in the left lane.
- 001: the car behind at 51 km/h, 16 m back, near the ego as it slows. The room to pull
  out granted behind the standing car (8 m) was dropped when the tracker gave that car a
  new track; the ego stood 7.2 m behind it, where no pass path clears it, to the end. Now
  the room stays with the vehicle, and the ego, all but stopped with it, passes once the
  left lane is free.

Each shown from the truth, then the verdicts."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from avsim.run.runner import RunResult
from world.actors.catalogue import CATALOGUE, DEFAULT_MODEL
from world.sensors.setup import Profile

pytestmark = [pytest.mark.slow, pytest.mark.acceptance]
FILE = "scenarios/acceptance/overtake_stopped_car_variants.yaml"
CAR = CATALOGUE[DEFAULT_MODEL["car"]].length  # [m] a `type: car` actor's body
EGO = 4.8  # [m] the ego's body
W = 3.5  # [m] lane width
POINTS = {  # seed, the standing car's station [m], the car behind's speed [km/h], station [m]
    "000": (3106916664, 183.393463, 73.048037, 28.273359),
    "001": (764341015, 196.24118, 51.433243, 79.510769),
}


def _run(run_scenario: Callable[..., RunResult], point: str) -> RunResult:
    seed, s_slow, kph, s_rear = POINTS[point]
    overrides = {"seed": seed, "actors.0.s": s_slow, "actors.1.speed_kph": kph,
                 "actors.1.s": s_rear}
    return run_scenario(FILE, record=False, profile=Profile.FAST, **overrides)


def _motion(result: RunResult) -> list[tuple[float, str, str, str]]:
    return [(c.t, c.source, c.target, c.reason) for c in result.state_changes
            if c.machine == "motion"]


def _verdicts(result: RunResult) -> None:
    c = {r.name: r for r in result.criteria}
    assert not any(r.failed for r in result.criteria), result.criteria
    assert c["no_collision"].value == 0 and c["tyres_in_lane"].passed
    assert c["completes"].passed
    assert result.metrics["collisions"] == 0


def test_000_keeps_right_before_the_faster_car_comes_up(
        run_scenario: Callable[..., RunResult]) -> None:
    result = _run(run_scenario, "000")
    log = result.log
    t, s = log.array("t"), log.array("station")
    slow_s = np.array(log.actor_station)[:, 0]
    rear_s, rear_d = np.array(log.actor_station)[:, 1], np.array(log.actor_offset)[:, 1]
    assert np.abs(rear_d - W).max() < 0.1  # the car behind kept the left lane ...
    assert np.abs(np.gradient(rear_s, t) - 73.048037 / 3.6).max() < 0.2  # ... never braking
    motion = _motion(result)
    out = next(m for m in motion if m[2] == "lane_change_left")
    i = int(np.searchsorted(t, out[0]))
    assert s[i] - rear_s[i] > 0.5 * (CAR + EGO) + 40.0  # the ego pulled out in front of it
    back = next(m for m in motion if m[2] == "lane_change_right")
    assert back[3] == "keep right: the right lane is free"
    j = int(np.searchsorted(t, back[0]))
    assert s[j] - slow_s[j] > 0.5 * (CAR + EGO)  # past the standing car
    assert rear_s[-1] > s[-1]  # the faster car went by
    _verdicts(result)


def test_001_stops_with_room_and_passes_once_the_lane_is_free(
        run_scenario: Callable[..., RunResult]) -> None:
    result = _run(run_scenario, "001")
    log = result.log
    t, s, v = log.array("t"), log.array("station"), log.array("speed")
    slow_s = np.array(log.actor_station)[:, 0]
    rear_s = np.array(log.actor_station)[:, 1]
    out = next((m for m in _motion(result) if m[2] == "lane_change_left"), None)
    assert out is not None, "the ego never pulled out to pass"
    i = int(np.searchsorted(t, out[0]))
    assert rear_s[i] - s[i] > 0.5 * (CAR + EGO)  # the car behind had gone by
    before = t < out[0]
    assert v[before].min() < 2.0  # the ego had all but stopped behind the standing car ...
    gap = slow_s[before] - s[before] - 0.5 * (CAR + EGO)
    assert gap[np.argmin(v[before])] > 9.0  # ... with room for a path that clears it
    assert s[-1] > slow_s[-1] + 30.0
    _verdicts(result)
