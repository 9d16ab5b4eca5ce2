"""Town situations under the default consumer receiver (the acceptance set):

- `acceptance/town_lights_left`: traffic lights everywhere; the ego follows a slower car
  through a green light to a red one, where it turns left on green (unprotected) across
  two oncoming cars, giving way to both;
- `acceptance/town_u_turn_corner`: `junctions: mixed`; the ego stops at a red light with a
  car queued behind it, then makes a U-turn at the town's corner with that car behind.

(The third, all-way stops with cross traffic, is `acceptance/town_stop_queue`:
`test_town_junctions.py`.) Each test shows from the truth that its situation happened,
then the verdicts."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from avsim.run.runner import RunResult
from world.hdmap import Control, Junction, Manoeuvre
from world.map.road import build_road_map
from world.sensors.setup import Profile
from world.spec import GnssSpec

pytestmark = [pytest.mark.slow, pytest.mark.acceptance]  # the acceptance set: `make acceptance`
HERE = Path(__file__).parents[2] / "scenarios" / "acceptance"
FRONT = 2.4  # [m] the ego's centre -> front bumper
STOPPED = 0.1  # [m/s]


@pytest.fixture(scope="module")
def lights_left(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run_scenario(str(HERE / "town_lights_left.yaml"), record=False, profile=Profile.FAST)


@pytest.fixture(scope="module")
def u_turn(run_scenario: Callable[..., RunResult]) -> RunResult:
    return run_scenario(str(HERE / "town_u_turn_corner.yaml"), record=False,
                        profile=Profile.FAST)


def _actor_xy(r: RunResult, actor_id: str) -> np.ndarray:
    """(T, 2) [m] an NPC's centre at each control tick, from its own route road."""
    k = [a.id for a in r.scenario.world.actors].index(actor_id)
    spec = r.scenario.world.actors[k].road
    assert spec is not None
    s = np.array(r.log.actor_station)[:, k]
    offset = np.array(r.log.actor_offset)[:, k]
    return build_road_map(spec).position(s, offset)


def _in_box(xy: np.ndarray, j: Junction) -> np.ndarray:
    return (np.abs(xy[:, 0] - j.x) <= j.half_width) & (np.abs(xy[:, 1] - j.y) <= j.half_width)


def _entered(r: RunResult, j: Junction) -> float:
    """[s] when the ego's front bumper went over the junction's stop line."""
    t, s = r.log.array("t"), r.log.array("station")
    over = s + FRONT > j.s_stop
    assert over.any(), j.index
    return float(t[np.argmax(over)])


def _states(r: RunResult, machine: str) -> list[str]:
    return [c.target for c in r.state_changes if c.machine == machine]


def _passes(r: RunResult) -> None:
    failed = [f"{c.name}: {c.note or c.value}" for c in r.criteria if c.failed]
    assert not failed, failed
    c = {x.name: x for x in r.criteria}
    assert c["completes"].passed and c["max_wait_with_right_of_way"].passed
    assert c["red_lights"].value is not None  # lights were crossed, none on red
    assert r.scenario.world.sensors.gnss == GnssSpec()  # the default, consumer receiver


# ---- town_lights_left -------------------------------------------------------------------------


def test_lights_everywhere_and_the_ego_follows_the_slower_car(lights_left: RunResult) -> None:
    road = build_road_map(lights_left.scenario.world.road)
    assert {j.control for j in road.junctions} == {Control.TRAFFIC_LIGHTS}
    ahead = next(a for a in lights_left.scenario.world.actors if a.id == "ahead")
    assert ahead.speed < lights_left.scenario.driver.set_speed - 3.0  # slower
    t, gap = lights_left.log.array("t"), lights_left.log.array("lead_gap")
    behind = np.isfinite(gap) & (gap < 30.0)
    assert float(np.sum(np.diff(t)[behind[1:]])) > 15.0  # it followed the car for 15 s +
    acc = _states(lights_left, "acc")
    assert "trail" in acc and "red_light" in acc


def test_the_unprotected_left_gives_way_to_both_oncoming_cars(lights_left: RunResult) -> None:
    road = build_road_map(lights_left.scenario.world.road)
    left = next(j for j in road.junctions if j.manoeuvre is Manoeuvre.LEFT)
    t = lights_left.log.array("t")
    entered = _entered(lights_left, left)
    for actor in ("oncoming_1", "oncoming_2"):
        inside = _in_box(_actor_xy(lights_left, actor), left)
        assert inside.any(), actor  # it came through the junction ...
        assert t[inside].max() < entered, actor  # ... before the ego went over its line
    assert "yield" in _states(lights_left, "acc")
    assert "turn_left" in _states(lights_left, "motion")
    _passes(lights_left)


# ---- town_u_turn_corner -----------------------------------------------------------------------


def test_the_u_turn_at_the_corner_with_a_car_behind(u_turn: RunResult) -> None:
    town = u_turn.scenario.world.town
    assert town is not None and town.junctions == "mixed"
    road = build_road_map(u_turn.scenario.world.road)
    corner = next(j for j in road.junctions if j.manoeuvre is Manoeuvre.U_TURN)
    assert corner.index == (town.blocks_x, town.blocks_y)  # the town's corner
    t, v = u_turn.log.array("t"), u_turn.log.array("speed")
    x, y = u_turn.log.array("x"), u_turn.log.array("y")
    behind = _actor_xy(u_turn, "behind")
    distance = np.hypot(behind[:, 0] - x, behind[:, 1] - y)
    # queued right behind the ego at the red light
    assert np.any((v < STOPPED) & (distance < 12.0))
    began = next(c.t for c in u_turn.state_changes
                 if c.machine == "motion" and c.target == "u_turn")
    k = int(np.searchsorted(t, began))
    assert distance[k] < 50.0  # the car was behind it as the U-turn began ...
    # ... and came round the corner after it (its right turn there cuts inside the box)
    at_corner = np.hypot(behind[:, 0] - corner.x, behind[:, 1] - corner.y) < 12.0
    assert at_corner.any() and t[at_corner].min() > began
    assert "u_turn" in _states(u_turn, "motion")
    _passes(u_turn)
