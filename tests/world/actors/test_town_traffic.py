"""Town drivers (`world.actors.town_traffic`): the vehicles too far to be followed are not
projected onto the route, and that changes no speed cap."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from avsim.scenario.load import load_scenario
from world.actors import town_traffic
from world.actors.town_traffic import FOLLOW_LANE_HALF, LOOK_AHEAD, TownDriver
from world.world import World


@pytest.fixture(scope="module")
def drivers() -> Iterator[list[TownDriver]]:
    world = World(load_scenario("town_route").world)  # its NPCs drive their own town routes
    try:
        found = [d for d in world.actors._drivers if d is not None]
        assert found
        yield found
    finally:
        world.close()


def others_near(driver: TownDriver, s: float, data: st.DataObject) -> np.ndarray:
    """Vehicle centres around the route at s: some on the route ahead or behind (within or
    beyond LOOK_AHEAD, on or off the lane), some anywhere in a 300 m square."""
    line = driver.road.line
    points = []
    for _ in range(data.draw(st.integers(0, 6))):
        if data.draw(st.booleans()):
            along = data.draw(st.floats(-2.0 * LOOK_AHEAD, 2.0 * LOOK_AHEAD))
            offset = data.draw(st.floats(-3.0 * FOLLOW_LANE_HALF, 3.0 * FOLLOW_LANE_HALF))
            station = min(max(s + along, 0.0), driver.road.length)
            x, y, _ = line.pose_one(station, offset)
        else:
            cx, cy, _ = line.pose_one(s, 0.0)
            x = cx + data.draw(st.floats(-150.0, 150.0))
            y = cy + data.draw(st.floats(-150.0, 150.0))
        points.append((x, y))
    return np.array(points, dtype=np.float64).reshape(-1, 2)


@settings(max_examples=300, deadline=None)
@given(data=st.data())
def test_the_reach_filter_changes_no_cap(drivers: list[TownDriver], data: st.DataObject,
                                         ) -> None:
    driver = data.draw(st.sampled_from(drivers))
    s = data.draw(st.floats(0.0, driver.road.length))
    speed = data.draw(st.floats(0.0, 15.0))
    others = others_near(driver, s, data)
    half = np.full(len(others), 2.4)
    filtered = driver._follow_cap(s, speed, others, half)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(town_traffic, "FOLLOW_REACH", math.inf)  # project every vehicle
        everything = driver._follow_cap(s, speed, others, half)
    assert filtered == everything


def test_a_vehicle_ahead_on_the_lane_caps_the_speed(drivers: list[TownDriver]) -> None:
    """The property above is not empty: a vehicle 20 m ahead on the lane is followed, and
    one 200 m to the side is not."""
    driver = drivers[0]
    s = 0.3 * driver.road.length
    ahead = np.array([driver.road.line.pose_one(s + 20.0, 0.0)[:2]])
    aside = ahead + np.array([[0.0, 200.0]])
    half = np.array([2.4])
    assert driver._follow_cap(s, 10.0, ahead, half) < 10.0
    assert driver._follow_cap(s, 10.0, aside, half) == math.inf
