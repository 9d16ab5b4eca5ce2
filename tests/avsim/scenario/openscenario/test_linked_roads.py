"""OpenSCENARIO positions on OpenDRIVE roads linked end to end: a position on the second
road is where that road's own geometry puts it, relative positions run on across a road's
end, and the scenario loads on the merged route."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from avsim.scenario.load import load_scenario
from avsim.scenario.openscenario.model import (
    LanePosition,
    RelativeLanePosition,
    RoadPosition,
)
from avsim.scenario.openscenario.resolve import Pose, PositionError, Resolver
from world.map.opendrive import Road, lane_centre_t, load_opendrive
from world.map.opendrive.route import build_route
from world.map.road import build_road_map

DATA = Path(__file__).with_name("data")
XOSC = DATA / "linked_roads.xosc"
XODR = Path(__file__).parents[3] / "world/map/opendrive/data/linked.xodr"
REAR_AXLE = 1.35  # [m] behind avsim's car's centre (vehicle_urdf)


def file_point(road: Road, lane_id: int, s: float, offset: float = 0.0) -> tuple[float, float]:
    """The map point of (lane `lane_id`, s) of the file road `road`, from its own geometry."""
    x, y, h = (float(v[0]) for v in road.plan_view.pose(np.array([s])))
    t = lane_centre_t(road, lane_id, s) + offset
    return x - t * math.sin(h), y + t * math.cos(h)


@pytest.fixture(scope="module")
def resolver() -> Resolver:
    return Resolver(build_route(load_opendrive(XODR)).chain)


def test_a_lane_position_on_the_second_road_is_that_roads_point(resolver: Resolver) -> None:
    road2 = load_opendrive(XODR).road("2")
    pose = resolver.resolve(LanePosition("2", "-1", 10.0, 0.0, None), {})
    assert math.dist((pose.x, pose.y), file_point(road2, -1, 10.0)) < 1e-9
    # the same point as the merged road's coordinates: road 2 starts at 100 m on it
    merged = resolver.road
    assert math.dist((pose.x, pose.y), file_point(merged, -1, 110.0)) < 1e-9
    heading = float(road2.plan_view.pose(np.array([10.0]))[2][0])
    assert math.remainder(pose.heading - heading, 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
    road_pose = resolver.resolve(RoadPosition("3", 20.0, -1.75, None), {})
    road3 = load_opendrive(XODR).road("3")
    assert math.dist((road_pose.x, road_pose.y), file_point(road3, -1, 20.0)) < 1e-9


def test_a_relative_lane_position_runs_on_across_a_roads_end(resolver: Resolver) -> None:
    """70 m ahead of road 2's s = 10 and one lane right: road 3's lane -2 at s = 20."""
    ego = resolver.resolve(LanePosition("2", "-1", 10.0, 0.0, None), {})
    lead = resolver.resolve(RelativeLanePosition("Ego", -1, 70.0, None, 0.0, None),
                            {"Ego": Pose(ego.x, ego.y, ego.heading)})
    road3 = load_opendrive(XODR).road("3")
    assert math.dist((lead.x, lead.y), file_point(road3, -2, 20.0)) < 1e-6


@pytest.mark.parametrize(("position", "problem"), [
    (LanePosition("7", "-1", 10.0, 0.0, None),
     "no road 7 in the OpenDRIVE file (roads: 1, 2, 3)"),
    (LanePosition("2", "-1", 70.0, 0.0, None), "s = 70 m is off road 2 (0 to 60 m)"),
    (RoadPosition("1", -1.0, 0.0, None), "s = -1 m is off road 1 (0 to 100 m)"),
    (LanePosition("3", "-4", 10.0, 0.0, None), "road 3 has no lane -4 at s = 10 m"),
])
def test_a_position_off_the_roads_names_its_road(resolver: Resolver, position: LanePosition,
                                                  problem: str) -> None:
    with pytest.raises(PositionError, match=f"^{re.escape(problem)}$"):
        resolver.resolve(position, {})


def test_the_scenario_loads_on_the_merged_route() -> None:
    scenario = load_scenario(XOSC, search_paths=(XODR.parent,))  # its road is found there
    assert scenario.story is not None
    assert scenario.story.chain.starts == {"1": 0.0, "2": 100.0, "3": 160.0}
    assert scenario.story.lane_ids == (-2, -1)
    road_map = build_road_map(scenario.world.road)
    road2, road3 = (load_opendrive(XODR).road(i) for i in ("2", "3"))
    # the ego: lane -1 (route lane 1) of road 2 at s = 10, its centre 1.35 m ahead
    x, y = file_point(road2, -1, 10.0)
    heading = float(road2.plan_view.pose(np.array([10.0]))[2][0])
    centre = (x + REAR_AXLE * math.cos(heading), y + REAR_AXLE * math.sin(heading))
    lane, s, _ = road_map.lane_at(centre)
    assert scenario.world.ego.lane == lane == 1
    assert scenario.world.ego.s == pytest.approx(s, abs=1e-9)
    assert 100.0 < s < 160.0 - REAR_AXLE  # on road 2's stretch of the map
    lead, parked = scenario.world.actors
    assert (lead.id, lead.lane, parked.id, parked.lane) == ("lead", 0, "parked", 0)
    _, s_lead, _ = road_map.lane_at(file_point(road3, -2, 20.0))
    assert lead.s == pytest.approx(s_lead + 1.5, abs=0.05)  # its box centre 1.5 m ahead
    _, s_parked, _ = road_map.lane_at(file_point(road3, -2, 50.0, 0.5))
    assert parked.s == pytest.approx(s_parked + 1.5, abs=0.05)
    assert s_parked > s_lead > 160.0  # both on road 3's stretch
