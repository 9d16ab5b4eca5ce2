"""The vendored ASAM/BMW ALKS (UN R157) scenario set as the scenario tests run it: each file
with its default parameters until its StopTrigger, under the `r157` criteria set, with the
`default` sensor profile: the `fast` one's LiDAR (half the columns) first sees the standing
pedestrian of 4.2.1 too late to stop for it from 60 km/h. `run(..., stack=TRUTH)` runs a file
on the privileged ground truth instead (profile `none`: `tests.scenarios.modes`)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from avsim.criteria.base import CriterionResult, Verdict
from avsim.run.runner import RunResult
from tests.scenarios.modes import SENSORS
from world.sensors.setup import Profile

ALKS = (Path(__file__).parents[1] / "data" / "alks" / "logical_scenarios"
        / "concrete_scenarios")
PROFILE = Profile.DEFAULT
LANE_WIDTH = 3.5  # [m] the ALKS road's
EGO_LANE = 1  # lane -4, the middle of the three: route lane 1, centre 3.5 m left of lane 0's
KPH = 1.0 / 3.6


def path(number: str) -> Path:
    """The file of ALKS scenario `number` (`4_4_1`)."""
    (found,) = ALKS.glob(f"alks_scenario_{number}_*.xosc")
    return found


def run(run_scenario: Callable[..., RunResult], number: str, stack: str = SENSORS,
        **overrides: object) -> RunResult:
    """ALKS scenario `number` in stack mode `stack` (`tests.scenarios.modes`)."""
    return run_scenario(str(path(number)), record=False, profile=PROFILE, criteria="r157",
                        stack=stack, **overrides)


def run_on_the_map(run_scenario: Callable[..., RunResult], number: str) -> RunResult:
    """A run that judges no perception: map and GNSS only (no camera or LiDAR), the GNSS an
    RTK receiver (a consumer one's metre of bias needs the camera's lane). The two 300 s
    free-driving files run so: with the cameras they would cost 7 min of a worker."""
    return run_scenario(str(path(number)), record=False, profile=None, criteria="r157",
                        **{"sensors.gnss": {"preset": "rtk"}})


def verdicts(result: RunResult) -> dict[str, CriterionResult]:
    return {c.name: c for c in result.criteria}


def failed(result: RunResult, ignore: tuple[str, ...] = ()) -> list[str]:
    return [f"{c.name}: {c.note or c.value}" for c in result.criteria
            if c.failed and c.name not in ignore]


def actor(result: RunResult, entity: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(stations, offsets from the route's reference line) [m] of an entity's body centre
    at each control tick (its actor id: the entity's name in lower case)."""
    k = [a.id for a in result.scenario.world.actors].index(entity.lower())
    return np.array(result.log.actor_station)[:, k], np.array(result.log.actor_offset)[:, k]


def in_ego_lane(offset: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Whether a body centre at `offset` lies in the ego's lane."""
    out: NDArray[np.bool_] = np.abs(offset - EGO_LANE * LANE_WIDTH) < 0.5 * LANE_WIDTH
    return out


def fired(result: RunResult, element: str) -> float | None:
    """[s] when a storyboard element of the story first started, None if never."""
    return next(e.fired_at for e in result.story if e.element == element)


def ended_by_stop_trigger(result: RunResult) -> bool:
    stop = fired(result, "StopTrigger")
    return stop is not None and abs(result.sim_time - stop) < 0.05


def passed(result: RunResult, name: str) -> bool:
    return verdicts(result)[name].verdict is Verdict.PASS


def stopped_short(result: RunResult, entity: str) -> float:
    """[m] how far the ego's front stood from the target's centre at the end (> 0: short)."""
    s, _ = actor(result, entity)
    front = result.log.array("station")[-1] + 2.4
    assert result.log.array("speed")[-1] < 0.1  # it stands
    return float(s[-1] - front)
