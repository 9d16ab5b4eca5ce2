"""On the shoulder the path is placed across the road by the camera's view of the shoulder's
one painted line (`planner.shoulder_line`): a pose estimate off across the shoulder (a GNSS
bias the camera's lane no longer corrects there) no longer parks the car on that line."""

from __future__ import annotations

import math

import numpy as np
import pytest

from perception.messages import EgoState, LaneBoundary, LaneEstimate, LaneView, PlannerInput
from planner.fsm.motion import Motion
from planner.messages import ReferencePath
from planner.planner import Planner, PlannerParams
from planner.shoulder_line import ShoulderLine, ShoulderLineParams, shifted
from tests.planner.maps import KPH, straight_road
from tests.vehicle import VEHICLE
from world.hdmap import SHOULDER, Lane

ROAD = straight_road("real", 1000.0, 50.0)
SHOULDER_LANE = ROAD.lane(SHOULDER)
W = float(SHOULDER_LANE.width_at(100.0))  # [m] the shoulder's width
DT = 0.05  # [s] planner tick
TRUE_LEFT = 0.4  # [m] how far left of where its estimate says the car truly is


def pose(lane: Lane, s: float, r: float, t: float, speed: float = 6.0) -> EgoState:
    xy = lane.position(s, r)
    return EgoState(t, float(xy[0]), float(xy[1]), float(lane.heading_at(s)), speed, 0.0,
                    0.0, 0.1)


def line_view(at: EgoState, left_y: float | None, age: float = 0.0) -> LaneView:
    """The camera's frame at pose `at`: one line fitted on the left at `left_y` [m] (vehicle
    frame, left +), the lane filter's one-line estimate around it."""
    left = None if left_y is None else LaneBoundary((left_y, 0.0, 0.0), 5.0, 25.0, 400)
    return LaneView(LaneEstimate(t=at.t, offset=0.0, heading_error=0.0, curvature=0.0,
                                 width=3.5, confidence=0.5, left=left, right=None, lines=1,
                                 age=age), at)


def seen_from(at: EgoState, r_true: float) -> LaneView:
    """The view of a car whose centre is truly `r_true` [m] left of the shoulder's centre:
    the shoulder's line (its left boundary) w/2 - r_true to its left."""
    return line_view(at, 0.5 * W - r_true)


def test_the_pose_error_across_the_shoulder_is_what_the_line_says() -> None:
    line = ShoulderLine(ShoulderLineParams(tau=1.0))
    error = 0.0
    for k in range(100):  # 5 s of ticks, a frame every other tick
        t = 1.0 + k * DT
        frame = round(t - t % 0.1, 9)  # the estimate at the frame: the shoulder's centre
        view = seen_from(pose(SHOULDER_LANE, 100.0, 0.0, frame), TRUE_LEFT)
        error = line.update(DT, view, SHOULDER_LANE, 100.0)
        if k == 0:
            assert error == pytest.approx(-TRUE_LEFT * DT / 1.0)  # from 0, smoothly
    assert error == pytest.approx(-TRUE_LEFT, abs=0.01)


def test_a_line_that_does_not_agree_a_prediction_or_no_line_leave_it_as_it_is() -> None:
    line = ShoulderLine()
    at = pose(SHOULDER_LANE, 100.0, 0.0, 1.0)
    lane0_left = line_view(at, 0.5 * W + 3.5)  # lane 0's left line, a lane width farther
    assert line.update(DT, lane0_left, SHOULDER_LANE, 100.0) == 0.0
    predicted = line_view(pose(SHOULDER_LANE, 100.0, 0.0, 1.1), 0.5 * W - TRUE_LEFT, age=0.3)
    assert line.update(DT, predicted, SHOULDER_LANE, 100.0) == 0.0
    assert line.update(DT, line_view(pose(SHOULDER_LANE, 100.0, 0.0, 1.2), None),
                       SHOULDER_LANE, 100.0) == 0.0
    assert line.update(DT, None, SHOULDER_LANE, 100.0) == 0.0
    took = line.update(DT, seen_from(pose(SHOULDER_LANE, 100.0, 0.0, 1.3), TRUE_LEFT),
                       SHOULDER_LANE, 100.0)
    assert took < 0.0
    line.reset()
    assert line.error == 0.0


def test_shifted_moves_each_point_along_its_normal() -> None:
    heading = np.array([0.0, 0.5 * math.pi])
    path = ReferencePath(xy=np.array([[0.0, 0.0], [1.0, 0.0]]), heading=heading,
                         curvature=np.zeros(2))
    moved = shifted(path, -0.4)  # to the right
    np.testing.assert_allclose(moved.xy, [[0.0, -0.4], [1.4, 0.0]], atol=1e-12)
    np.testing.assert_array_equal(moved.heading, heading)
    assert shifted(path, 0.0) is path


def _pulled_over(p: Planner, s: float, t: float) -> tuple[float, float]:
    """Tick a flat-tyred car at 6 m/s whose estimate is exactly on its plan's path (the
    pose on the lane kept's centre once on the shoulder) until it keeps the shoulder and
    no path of a change is in hand: (station [m], time [s]) then."""
    r, lane = 0.0, ROAD.lane(0)
    for _ in range(2000):
        plan = p.update(PlannerInput(pose(lane, s, r, t), flat_tyre=True))
        if plan.lane == SHOULDER and plan.motion is Motion.LANE_KEEP:
            return s, t
        if plan.lane == SHOULDER:
            lane = SHOULDER_LANE
            r = float(SHOULDER_LANE.local_coordinates(plan.path.xy[10], s)[1])
        s, t = s + 6.0 * DT, t + DT
    raise AssertionError("never pulled over")


def test_on_the_shoulder_the_path_moves_by_the_pose_error_the_line_tells() -> None:
    p = Planner(ROAD, PlannerParams(50.0 * KPH, 180.0 * KPH, VEHICLE, lane=0, camera=False))
    s, t = _pulled_over(p, 100.0, 1.0)
    for _ in range(100):  # 5 s; the estimate on the shoulder's centre, the car 0.4 m left
        at = pose(SHOULDER_LANE, s, 0.0, t)
        plan = p.update(PlannerInput(at, lane=seen_from(at, TRUE_LEFT), flat_tyre=True))
        s, t = s + 6.0 * DT, t + DT
    assert plan.lane == SHOULDER
    _, r = SHOULDER_LANE.local_coordinates(plan.path.xy, s)
    np.testing.assert_allclose(r, -TRUE_LEFT, atol=0.01)  # where the car's estimate must be
    #   for the car to be on the shoulder's centre
