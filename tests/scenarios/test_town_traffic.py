"""Town traffic that flows (issue K 6): `acceptance/town_traffic`, a 4 x 4 town (lights and
all-way stops), 20 NPC cars and the ego on long routes, 10 simulated minutes. Nobody stands
longer than 60 s while it has the right of way (`max_wait_with_right_of_way`, judged from
the truth), and the ego touches nothing. The checks that the situation happened: the ego
drove through many junctions of both kinds, stood at all-way stops and at red lights, and
every NPC kept driving for the whole run.

`fast` is the cheapest profile that can drive this town: the lights are read by the front
camera and the other cars seen by the LiDAR (`none` has neither)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from avsim.run.runner import RunResult
from world.hdmap import Control
from world.map.road import build_road_map
from world.sensors.setup import Profile

pytestmark = [pytest.mark.slow, pytest.mark.acceptance]  # the acceptance set: `make acceptance`
SCENARIO = str(Path(__file__).parents[2] / "scenarios" / "acceptance" / "town_traffic.yaml")
FRONT = 2.4  # [m] the ego's centre -> front bumper


@pytest.fixture(scope="module")
def town(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run_scenario(SCENARIO, record=False, profile=Profile.FAST)


def test_nobody_waits_with_the_right_of_way_and_nothing_is_touched(town: RunResult) -> None:
    c = {r.name: r for r in town.criteria}
    assert c["max_wait_with_right_of_way"].passed, c["max_wait_with_right_of_way"]
    assert c["no_collision"].passed, c["no_collision"]
    assert not any(r.failed for r in town.criteria), town.criteria
    assert town.sim_time >= 600.0 - 1e-6  # the whole ten minutes


def test_the_ego_drove_through_junctions_of_both_kinds(town: RunResult) -> None:
    road = build_road_map(town.scenario.world.road)
    s = town.log.array("station")
    passed = [j for j in road.junctions if s.max() + FRONT > j.s_enter]
    kinds = {j.control for j in passed}
    assert len(passed) >= 15 and {Control.STOP_SIGNS, Control.TRAFFIC_LIGHTS} <= kinds
    c = {r.name: r for r in town.criteria}
    assert c["stop_signs"].passed and c["red_lights"].passed  # it kept to both


def test_every_npc_kept_driving(town: RunResult) -> None:
    t = town.log.array("t")
    st = np.array(town.log.actor_station)
    late = t > t[-1] - 120.0
    for k, actor in enumerate(town.scenario.world.actors):
        assert st[-1, k] - st[0, k] > 1500.0, actor.id  # kilometres through the town
        assert np.ptp(st[late, k]) > 50.0, actor.id  # and still on the move at the end
