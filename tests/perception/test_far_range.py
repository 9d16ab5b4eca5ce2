"""How far ahead a stationary car is found: detector and tracker on synthetic scans of the
default profile's LiDAR (VLP-16-like, 1800 columns, on the roof 1.57 m up).

Beyond about 32 m only the -1 deg ring still reaches a car ahead (the -3 deg ring meets the
ground first) and the +1 deg ring passes over its roof; the -1 deg ring crosses the car's
rear ever lower with range, under the detector's ``min_top`` beyond REACH (72.8 m). That is
the sensor's limit, not the region of interest's (60 m before issue K: a stopped car was
first tracked 58 m ahead, too late for a comfortable stop from 60 km/h).
"""

from __future__ import annotations

import math

import pytest

from perception.messages import EgoState, ObjectClass, Track
from perception.objects import DetectorParams, ObjectDetector
from perception.tracking import MultiObjectTracker
from tests.perception.lidar_synth import CAR, LIDAR_MOUNT, cast, lidar_info, on_ground

LOWEST_FAR_RING = math.radians(-1.0)  # [rad] the lowest ring that clears the ground at 60 m+
REACH = (LIDAR_MOUNT.z - DetectorParams().min_top) / math.tan(-LOWEST_FAR_RING)  # [m] 72.8
V = 60.0 / 3.6  # [m/s] the ego's speed in the approach
SCAN = 0.1  # [s] the LiDAR's period


def rear_ahead(rear: float) -> float:
    """[m] the centre of a car (the catalogue's sedan) whose rear is `rear` [m] ahead."""
    return rear + 0.5 * CAR[0]


@pytest.mark.parametrize("rear", [40.0, 55.0, 65.0, 70.0, REACH - 0.5])
def test_a_stationary_car_ahead_is_found_as_far_as_a_ring_crosses_it_above_min_top(
        rear: float) -> None:
    box = on_ground(rear_ahead(rear), 0.0, CAR)
    found = ObjectDetector().detect(cast(lidar_info(), [box], seed=int(rear)))
    assert len(found) == 1, found
    det = found[0]
    assert det.cls is ObjectClass.CAR
    assert det.x - 0.5 * det.length == pytest.approx(rear, abs=0.15)  # the rear where it is
    assert det.y == pytest.approx(0.0, abs=0.3)


@pytest.mark.parametrize("rear", [REACH + 1.0, 85.0, 95.0])
def test_beyond_the_reach_the_ring_meets_it_too_low_and_nothing_is_found(rear: float) -> None:
    """The sensor's limit: a cluster this low cannot be told from the ground's clutter."""
    box = on_ground(rear_ahead(rear), 0.0, CAR)
    assert ObjectDetector().detect(cast(lidar_info(), [box], seed=int(rear))) == ()


def approach(start: float, scans: int) -> list[tuple[float, tuple[Track, ...]]]:
    """(rear range [m], confirmed tracks) at each scan of an ego driving at V straight at a
    stopped car whose rear is `start` [m] ahead at t = 0."""
    detector, tracker = ObjectDetector(), MultiObjectTracker()
    out = []
    for k in range(scans):
        t = k * SCAN
        rear = start - V * t
        scan = cast(lidar_info(), [on_ground(rear_ahead(rear), 0.0, CAR)], seed=k)
        ego = EgoState(t=t, x=V * t, y=0.0, heading=0.0, speed=V, yaw_rate=0.0,
                       steering_angle=0.0, position_sigma=0.05)
        out.append((rear, tracker.update(t, ego, detector.detect(scan))))
    return out


def test_a_stopped_car_approached_at_60_kph_is_tracked_from_68_m_and_stands_still() -> None:
    """Found at REACH, confirmed two scans later (3 of 5 hits), 68.3 m ahead (58 m before
    the region of interest reached the LiDAR's range). Its speed along the road, the lead's
    speed to the planner, is nil from the first (a new track starts at rest); across it, the
    first scans' few returns (a column more or less at an edge moves the centre by 0.1 m)
    give up to 2 m/s, within the filter's own uncertainty then, gone three scans later."""
    history = approach(95.0, 40)
    k = next(i for i, (_, tracks) in enumerate(history) if tracks)
    rear, _ = history[k]
    assert REACH - 3 * V * SCAN <= rear <= REACH
    assert rear > 68.0  # the figure: 68.3 m
    for j, (_, tracks) in enumerate(history[k:]):
        (track,) = tracks
        assert track.cls is ObjectClass.CAR
        assert abs(track.vx) < 0.3
        if j >= 3:
            assert math.hypot(track.vx, track.vy) < 0.5
