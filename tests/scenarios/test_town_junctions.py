"""Junctions that flow (issue K 5 and 6): the two deadlocks of issue K, as scenarios.

- `acceptance/town_stop_queue`: the ego follows an NPC (`ahead`) to an all-way stop while
  cars come from the three other arms; the NPCs cross in order of arrival (first to
  stop at its line, first to go), `ahead` among them, and the ego, queued behind `ahead`,
  moves up to the line and makes its own stop there.
- `acceptance/town_light_queue`: the ego follows `ahead` to a red light; on green both go.
  `ahead`'s route ends at the next light, and it leaves the town there instead of
  standing at the line for good with the ego behind it.

Both: nobody stands longer than 60 s with the right of way (`max_wait_with_right_of_way`,
from the truth). Each test checks that its situation happened."""

from __future__ import annotations

from collections.abc import Callable
from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest

from avsim.run.runner import RunResult
from world.map.road import build_road_map
from world.sensors.setup import Profile

pytestmark = [pytest.mark.slow, pytest.mark.acceptance]  # the acceptance set: `make acceptance`
HERE = Path(__file__).parents[2] / "scenarios" / "acceptance"
FRONT = 2.4  # [m] the ego's centre -> front bumper
TIE = 1.0  # [s] arrivals this close are a tie (`world.actors.all_way_stop.TIE`)


@pytest.fixture(scope="module")
def stop_queue(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run_scenario(str(HERE / "town_stop_queue.yaml"), record=False, profile=Profile.FAST)


@pytest.fixture(scope="module")
def light_queue(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run_scenario(str(HERE / "town_light_queue.yaml"), record=False,
                        profile=Profile.FAST)


def _npc_at_junction(r: RunResult, k: int, junction: tuple[int, int]) -> tuple[float, float]:
    """([s] when NPC k stood at its line of `junction`, [s] when its front went over it)."""
    t = r.log.array("t")
    actor = r.scenario.world.actors[k]
    assert actor.road is not None and actor.model is not None
    road = build_road_map(actor.road)
    j = next(j for j in road.junctions if j.index == junction)
    front = np.array(r.log.actor_station)[:, k] + 0.5 * actor.model.length
    v = np.gradient(front, t)
    stood = (np.abs(v) < 0.3) & (front > j.s_stop - 1.5) & (front <= j.s_stop)
    assert stood.any(), actor.id
    over = front > j.s_stop
    assert over.any(), actor.id
    return float(t[stood][0]), float(t[over][0])


def test_the_all_way_stop_goes_in_order_of_arrival(stop_queue: RunResult) -> None:
    names = [a.id for a in stop_queue.scenario.world.actors]
    times = {n: _npc_at_junction(stop_queue, k, (1, 1)) for k, n in enumerate(names)
             if n != "behind_north"}  # queued behind from_north: arrives when it moved up
    order = sorted(times, key=lambda n: times[n][0])
    went = sorted(times, key=lambda n: times[n][1])
    for a, b in pairwise(order):
        if times[b][0] - times[a][0] >= TIE:  # not a tie: the earlier went first
            assert went.index(a) < went.index(b), (a, b, times)
    arrivals = sorted(t for t, _ in times.values())
    assert arrivals[-1] - arrivals[0] < 20.0  # they did meet there: the situation happened


def test_the_queued_ego_moves_up_and_goes_after_the_npc_ahead(stop_queue: RunResult) -> None:
    t, v, s = (stop_queue.log.array(x) for x in ("t", "speed", "station"))
    road = build_road_map(stop_queue.scenario.world.road)
    j = road.junctions[0]
    k = [a.id for a in stop_queue.scenario.world.actors].index("ahead")
    ahead_stood, ahead_went = _npc_at_junction(stop_queue, k, (1, 1))
    queued = (t > ahead_stood) & (t < ahead_went) & (s + FRONT < j.s_stop - 5.0)
    assert np.any(queued & (v < 0.5))  # it waited behind ahead, short of the line
    over = float(t[np.argmax(s + FRONT > j.s_stop)])
    assert over > ahead_went  # it went after ahead
    c = {r.name: r for r in stop_queue.criteria}
    assert c["max_wait_with_right_of_way"].passed, c["max_wait_with_right_of_way"]
    assert c["no_collision"].passed and c["completes"].passed


def test_the_queued_ego_makes_its_own_stop_at_the_line(stop_queue: RunResult) -> None:
    c = {r.name: r for r in stop_queue.criteria}
    assert c["stop_signs"].passed, c["stop_signs"]


def test_the_npc_ahead_goes_on_green_and_leaves_at_its_route_end(light_queue: RunResult,
                                                                   ) -> None:
    t, s = light_queue.log.array("t"), light_queue.log.array("station")
    k = [a.id for a in light_queue.scenario.world.actors].index("ahead")
    ahead = light_queue.scenario.world.actors[k]
    assert ahead.road is not None
    st = np.array(light_queue.log.actor_station)[:, k]
    end = build_road_map(ahead.road).length
    assert st.max() > end - 5.0  # it reached its route's end ...
    road = build_road_map(light_queue.scenario.world.road)
    last = road.junctions[-1]
    assert s.max() + FRONT > last.s_exit  # ... and the ego drove on through that junction
    c = {r.name: r for r in light_queue.criteria}
    assert not any(r.failed for r in light_queue.criteria), light_queue.criteria
    assert c["red_lights"].value is not None and c["completes"].passed
    assert "red_light" in [x.target for x in light_queue.state_changes if x.machine == "acc"]
    assert float(t[-1]) < light_queue.scenario.duration  # done before the time ran out
