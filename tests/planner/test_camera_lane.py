"""The camera's lane as a map-frame path, and the lead vehicle from tracks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from perception.messages import EgoState, LaneEstimate, ObjectClass, Track
from planner.camera_lane import camera_lane_path
from planner.lead import LeadParams, select_lead
from tests.vehicle import VEHICLE

FRONT = VEHICLE.front_overhang  # [m]


def pose(x: float = 10.0, y: float = -3.0, heading: float = 0.7) -> EgoState:
    return EgoState(t=1.0, x=x, y=y, heading=heading, speed=10.0, yaw_rate=0.0,
                    steering_angle=0.0, position_sigma=0.05)


def lane(offset: float = 0.0, heading_error: float = 0.0, curvature: float = 0.0) -> LaneEstimate:
    return LaneEstimate(t=1.0, offset=offset, heading_error=heading_error,
                        curvature=curvature, width=3.5, confidence=0.9, left=None, right=None)


def test_centred_straight_lane_is_the_car_axis() -> None:
    p = pose()
    path = camera_lane_path(lane(), p, behind=5.0, ahead=30.0, spacing=0.5)
    d = path.xy - [p.x, p.y]
    along = d @ [math.cos(p.heading), math.sin(p.heading)]
    across = d @ [-math.sin(p.heading), math.cos(p.heading)]
    np.testing.assert_allclose(across, 0.0, atol=1e-12)
    assert along[0] == pytest.approx(-5.0) and along[-1] == pytest.approx(30.0)
    np.testing.assert_allclose(path.heading, p.heading)
    np.testing.assert_allclose(path.curvature, 0.0)


def test_offset_heading_error_and_curvature() -> None:
    """The car 0.4 m left of the centre and 2 deg left of the lane, the lane curving left."""
    p = pose(heading=0.0, x=0.0, y=0.0)
    est = lane(offset=0.4, heading_error=math.radians(2.0), curvature=1 / 100)
    path = camera_lane_path(est, p, behind=0.0, ahead=20.0, spacing=0.5)
    assert path.xy[0, 1] == pytest.approx(-0.4)  # the centre is right of the car
    assert path.heading[0] == pytest.approx(-math.radians(2.0))
    # the curvature of y(x) at x = 0, where the slope is -tan(2 deg)
    assert path.curvature[0] == pytest.approx(0.01 / (1 + math.tan(math.radians(2.0)) ** 2) ** 1.5)
    x = path.xy[:, 0]
    np.testing.assert_allclose(path.xy[:, 1], [est.centre_y(v) for v in x], atol=1e-12)


def track(rel_x: float, rel_y: float, vx: float, ident: int = 1,
          cls: ObjectClass = ObjectClass.CAR) -> Track:
    return Track(id=ident, t=1.0, x=rel_x, y=rel_y, vx=vx, vy=0.0, rel_x=rel_x, rel_y=rel_y,
                 rel_vx=vx - 10.0, rel_vy=0.0, length=4.6, width=1.8, height=1.5, yaw=0.0,
                 cls=cls, hits=5, misses=0, position_sigma=0.1)


def test_lead_is_the_nearest_in_lane_track_ahead() -> None:
    p = LeadParams()
    tracks = [track(40.0, 0.3, 8.0, 1), track(25.0, 3.5, 5.0, 2), track(-10.0, 0.0, 9.0, 3),
              track(60.0, -5.0, 8.0, 4)]
    lead = select_lead(tracks, lambda x: 0.0, 0.0, p, FRONT)
    assert lead is not None and lead.track_id == 1
    assert lead.gap == pytest.approx(40.0 - FRONT - 2.3)
    assert lead.speed == pytest.approx(8.0) and lead.t == 1.0
    # its speed is along the ego's heading: a car crossing at right angles has none
    assert select_lead(tracks, lambda x: 0.0, math.pi / 2, p, FRONT).speed == pytest.approx(0.0)
    # the lane bends right: the car at (60, -5) is in it, the one at (40, 0.3) is not
    lead = select_lead(tracks, lambda x: -5.0 * (x / 60.0) ** 2, 0.0, p, FRONT)
    assert lead is not None and lead.track_id == 4
    assert select_lead([track(30.0, 0.0, 5.0, cls=ObjectClass.OTHER)], lambda x: 0.0, 0.0,
                       p, FRONT) is None
