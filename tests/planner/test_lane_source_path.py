"""The lane source says what the path comes from: the camera's lane only while it is the
lane kept; the map's otherwise, and then the source says so (ACQUIRING). At the start,
before the camera's lane has corrected the pose across the lane, the map path holds the
car's offset instead of steering to a lane centre placed by the GNSS error."""

from __future__ import annotations

import math

import numpy as np
import pytest

from perception.messages import EgoState, LaneEstimate, LaneView, PlannerInput
from planner.fsm.lane_source import LaneSource
from planner.planner import Planner, PlannerParams
from tests.planner.maps import KPH, straight_road
from tests.vehicle import VEHICLE
from world.hdmap import RoadMap

ROAD = straight_road("real", 1000.0, 50.0, ())


def ego(road: RoadMap, s: float, r: float, t: float) -> EgoState:
    xy = road.lane(0).position(s, r)
    return EgoState(t, float(xy[0]), float(xy[1]), 0.0, 12.0, 0.0, 0.0, 0.1)


def view(pose: EgoState, offset: float, confidence: float = 0.9) -> LaneView:
    return LaneView(LaneEstimate(t=pose.t, offset=offset, heading_error=0.0, curvature=0.0,
                                 width=3.5, confidence=confidence, left=None, right=None), pose)


def camera_planner() -> Planner:
    return Planner(ROAD, PlannerParams(50.0 * KPH, 180.0 * KPH, VEHICLE, lane=0, camera=True))


def test_before_the_lane_is_seen_the_map_path_holds_the_offset() -> None:
    p = camera_planner()
    plan = p.update(PlannerInput(ego(ROAD, 100.0, 0.8, 0.0)))
    assert plan.lane_source is LaneSource.ACQUIRING
    _, r = ROAD.lane(0).local_coordinates(plan.path.xy)
    np.testing.assert_allclose(r, 0.8, atol=1e-9)  # parallel to the lane, through the car


def test_the_source_follows_what_the_path_is() -> None:
    p = camera_planner()
    pose = ego(ROAD, 100.0, 0.2, 0.1)
    seen = p.update(PlannerInput(pose, lane=view(pose, 0.2)))  # the lane kept: the camera's
    assert seen.lane_source is LaneSource.CAMERA
    _, r = ROAD.lane(0).local_coordinates(seen.path.xy)
    assert r[0] == pytest.approx(0.0, abs=1e-6)  # the camera's lane centre
    pose = ego(ROAD, 101.2, 0.2, 0.2)
    other = p.update(PlannerInput(pose, lane=view(pose, 0.2 - 3.5)))  # the lane beside
    assert other.lane_source is LaneSource.ACQUIRING
    assert any(c.machine == "lane_source" and "another lane" in c.reason
               for c in other.changes)
    _, r = ROAD.lane(0).local_coordinates(other.path.xy)
    np.testing.assert_allclose(r, 0.0, atol=1e-9)  # the map's lane kept, its centre
    pose = ego(ROAD, 102.4, 0.1, 0.3)
    back = p.update(PlannerInput(pose, lane=view(pose, 0.1)))
    assert back.lane_source is LaneSource.CAMERA
    assert not math.isnan(back.path.xy[0, 0])
