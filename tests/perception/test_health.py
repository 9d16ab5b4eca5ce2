"""Sensor health (`perception.health`): each fault noticed from the data alone, and sound
data never taken for a fault."""

from __future__ import annotations

import math

import numpy as np

from perception.health import HealthMonitor, HealthParams
from perception.messages import SensorHealth
from world.frames import CameraFrame, CameraInfo, GnssFix, LidarInfo, LidarScan, SensorMount

MOUNT = SensorMount(0.0, 0.0, 1.5)
CAMERA = CameraInfo("front", 64, 48, 1.4, MOUNT)
LIDAR = LidarInfo((0.0,), 4, 100.0, MOUNT)
P = HealthParams()


def scene(seed: int) -> CameraFrame:
    rgb = np.random.default_rng(seed).integers(0, 255, (48, 64, 3), dtype=np.uint8)
    return CameraFrame(0.1 * seed, CAMERA, rgb)


def scan(t: float, points: int = 100) -> LidarScan:
    return LidarScan(t, LIDAR, np.ones((points, 3), np.float32), np.zeros(points, np.uint8),
                     np.zeros(points, np.uint16))


def fix(t: float, x: float, valid: bool = True) -> GnssFix:
    return GnssFix(t, x, 0.0, 0.0, 1.2, 0.01, valid)


def test_a_changing_scene_is_sound() -> None:
    health = HealthMonitor()
    for k in range(5):
        assert health.camera(scene(k), 10.0, 0.1 * k + 0.1) is None
    assert health.health(0.45) == SensorHealth()


def test_a_black_or_flat_frame_carries_no_information() -> None:
    health = HealthMonitor()
    health.camera(scene(1), 10.0, 0.2)
    flat = CameraFrame(0.2, CAMERA, np.full((48, 64, 3), 120, np.uint8))
    fault = health.camera(flat, 10.0, 0.3)
    assert fault is not None and fault.startswith("camera frame carries no information")
    assert health.health(0.25).camera == fault
    assert health.camera(scene(3), 10.0, 0.4) is None  # sound again with the next real frame


def test_a_repeated_frame_is_frozen_while_moving_and_stays_so_until_it_changes() -> None:
    health = HealthMonitor()
    health.camera(scene(1), 10.0, 0.2)
    same = scene(1)
    assert health.camera(CameraFrame(0.2, CAMERA, same.rgb), 0.5, 0.3) is None  # a still scene
    fault = health.camera(CameraFrame(0.3, CAMERA, same.rgb), 5.0, 0.4)
    assert fault is not None and "frozen" in fault
    # the car has stopped: the same image is still the frozen one
    assert health.camera(CameraFrame(0.4, CAMERA, same.rgb), 0.0, 0.5) is not None
    assert health.camera(scene(5), 0.0, 0.6) is None


def test_missing_frames_and_scans_are_noticed_after_their_timeouts() -> None:
    health = HealthMonitor()
    assert health.health(10.0) == SensorHealth()  # nothing seen yet: nothing missed
    health.camera(scene(1), 10.0, 0.2)
    health.scan(scan(0.1), 0.2)
    assert health.health(0.1 + P.lidar_timeout).lidar is None
    lost = health.health(0.1 + P.lidar_timeout + 0.05)
    assert lost.lidar == "no LiDAR scan for 0.6 s"
    assert lost.camera == "no camera frame for 0.6 s"
    assert health.scan(scan(0.7, points=0), 0.8) == "LiDAR scan with no return"
    assert health.health(0.8).lidar == "LiDAR scan with no return"
    assert health.scan(scan(0.8), 0.9) is None
    assert health.health(0.85).lidar is None


def test_a_gnss_outage_is_noticed_after_its_timeout() -> None:
    health = HealthMonitor()
    assert health.fix(fix(0.0, 0.0), None).accepted
    for k in range(1, 40):
        check = health.fix(fix(0.1 * k, math.nan, valid=False), (0.0, 0.0, 0.3))
        assert not check.accepted
    assert health.health(P.gnss_timeout).gnss is None
    assert health.health(P.gnss_timeout + 0.1).gnss == "no valid GNSS fix for 3.1 s"
    assert health.fix(fix(4.0, 0.2), (0.0, 0.0, 0.3)).accepted
    assert health.health(4.0).gnss is None


def test_a_fix_off_the_odometry_s_prediction_by_more_than_its_gate_is_rejected() -> None:
    health = HealthMonitor()
    health.fix(fix(0.0, 0.0), None)
    ok = health.fix(fix(0.1, 4.0), (0.0, 0.0, 0.3))  # within the 5 m gate
    assert ok.accepted and ok.gate == P.gnss_gate
    jumped = health.fix(fix(0.2, 20.0), (0.0, 0.0, 0.3))
    assert not jumped.accepted and jumped.distance == 20.0
    assert health.health(0.2).gnss == ("GNSS fix 20.0 m from the odometry's prediction "
                                       "(gate 5.0 m)")
    wide = health.fix(fix(0.3, 20.0), (0.0, 0.0, 5.0))  # an uncertain prediction: wider
    assert wide.gate == P.gnss_gate_sigmas * math.hypot(5.0, 1.2) and wide.accepted
    assert health.health(0.3).gnss is None


def test_a_frame_or_scan_older_than_the_period_allows_is_late() -> None:
    health = HealthMonitor()
    assert health.camera(scene(1), 10.0, 0.1 + P.max_age) is None
    late = health.camera(scene(2), 10.0, 0.2 + P.max_age + 0.05)
    assert late == f"camera frame 0.30 s old at delivery (at most {P.max_age:g} s)"
    assert health.scan(scan(1.0), 1.0 + P.max_age) is None
    late = health.scan(scan(1.1), 1.5)
    assert late == f"LiDAR scan 0.40 s old at delivery (at most {P.max_age:g} s)"
    assert health.health(1.5).lidar == late


def test_a_dark_featureless_part_of_the_view_is_a_partial_occlusion() -> None:
    health = HealthMonitor()
    frame = scene(1)
    covered = frame.rgb.copy()
    covered[:, :32] = 0  # the left half
    assert health.camera(CameraFrame(0.2, CAMERA, covered), 10.0, 0.3) is None  # perceived
    assert health.health(0.3).occlusion == ("50% of the camera frame dark and featureless "
                                            "(partly occluded)")
    sky = frame.rgb.copy()
    sky[:24] = 200  # a bright uniform upper half (a clear sky) is no occlusion
    health.camera(CameraFrame(0.3, CAMERA, sky), 10.0, 0.4)
    assert health.health(0.4) == SensorHealth()
