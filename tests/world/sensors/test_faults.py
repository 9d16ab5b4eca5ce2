"""Sensor faults on the data the stack receives (`world.sensors.faults`): what each does to a
reading, and the two sensing pipelines giving bitwise the same faulty data."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from tests.world.sensors.test_pipeline import assert_same, drive
from world.frames import CameraFrame, CameraInfo, GnssFix, LidarInfo, LidarScan, SensorMount
from world.hdmap import Side
from world.sensors.faults import FaultInjector
from world.sensors.sensor import Reading
from world.spec import (
    CameraBlackout,
    CameraFreeze,
    CameraOcclusion,
    EventSpec,
    GnssJump,
    GnssOutage,
    LidarOutage,
    SensorDelay,
    TimeTrigger,
)

MOUNT = SensorMount(0.0, 0.0, 1.5)
CAMERA = CameraInfo("front", 8, 6, 1.4, MOUNT)
LIDAR = LidarInfo((0.0,), 4, 100.0, MOUNT)


def image(value: int) -> np.ndarray:
    return np.full((6, 8, 3), value, dtype=np.uint8)


def camera(t: float, value: int, name: str = "front") -> Reading:
    return Reading(name, CameraFrame(t, replace(CAMERA, name=name), image(value)))


def scan(t: float) -> Reading:
    points = np.ones((3, 3), dtype=np.float32)
    return Reading("lidar", LidarScan(t, LIDAR, points, np.zeros(3, np.uint8),
                                      np.zeros(3, np.uint16)), truth="truth")


def fix(t: float) -> Reading:
    return Reading("gnss", GnssFix(t, 10.0, 20.0, 0.5, 1.2, 0.01))


def frame_of(readings: tuple[Reading, ...], sensor: str) -> object:
    return next(r.frame for r in readings if r.sensor == sensor)


def test_a_blackout_blacks_out_its_camera_only() -> None:
    injector = FaultInjector()
    out = injector.apply((camera(0.1, 80), camera(0.1, 90, "left")),
                         (CameraBlackout("front", 1.0),))
    front, left = (r.frame for r in out)
    assert isinstance(front, CameraFrame) and isinstance(left, CameraFrame)
    assert front.t == 0.1 and not front.rgb.any()
    assert np.array_equal(left.rgb, image(90))


def test_a_frozen_camera_repeats_the_image_delivered_before_the_fault() -> None:
    injector = FaultInjector()
    freeze = (CameraFreeze("front", 1.0),)
    got = []
    for k, faults in enumerate(((), (), freeze, freeze, (), freeze)):
        out = injector.apply((camera(0.1 * k, 10 * (k + 1)),), faults)
        frame = frame_of(out, "front")
        assert isinstance(frame, CameraFrame) and frame.t == 0.1 * k  # time runs on
        got.append(int(frame.rgb[0, 0, 0]))
    assert got == [10, 20, 20, 20, 50, 50]  # a new freeze holds the last image again


def test_an_occlusion_blacks_out_a_strip_from_its_side() -> None:
    injector = FaultInjector()
    out = injector.apply((camera(0.1, 80),), (CameraOcclusion("front", 0.25, Side.RIGHT, 1.0),))
    frame = frame_of(out, "front")
    assert isinstance(frame, CameraFrame)
    assert not frame.rgb[:, 6:].any() and (frame.rgb[:, :6] == 80).all()
    out = injector.apply((camera(0.2, 80),), (CameraOcclusion("front", 0.5, Side.LEFT, 1.0),))
    frame = frame_of(out, "front")
    assert isinstance(frame, CameraFrame)
    assert not frame.rgb[:, :4].any() and (frame.rgb[:, 4:] == 80).all()


def test_a_delayed_sensor_delivers_its_capture_from_the_delay_before() -> None:
    injector = FaultInjector({"lidar": 0.3})
    delay = (SensorDelay("lidar", 0.3, 1.0),)
    got = []
    for k in range(8):
        faults = delay if 2 <= k < 6 else ()
        out = injector.apply((scan(0.1 * k),), faults)
        got.append(round(out[0].frame.t, 3) if out else None)
    # none 0.3 s older at 0.2 s; then the captures 0.3 s old; on time when it is over
    assert got == [0.0, 0.1, None, 0.0, 0.1, 0.2, 0.6, 0.7]


def test_a_lidar_outage_drops_the_scan_and_a_gnss_outage_invalidates_the_fix() -> None:
    injector = FaultInjector()
    out = injector.apply((camera(0.1, 80), scan(0.1)), (LidarOutage(1.0),))
    assert [r.sensor for r in out] == ["front"]
    out = injector.apply((fix(0.1),), (GnssOutage(1.0),))
    gnss = frame_of(out, "gnss")
    assert isinstance(gnss, GnssFix) and not gnss.valid and math.isnan(gnss.x)
    assert injector.apply((scan(0.2),), ())[0].truth == "truth"


def test_a_gnss_jump_moves_the_fix_by_its_offset() -> None:
    out = FaultInjector().apply((fix(0.1),), (GnssJump((15.0, -3.0), 1.0),))
    gnss = frame_of(out, "gnss")
    assert isinstance(gnss, GnssFix) and gnss.valid
    assert (gnss.x, gnss.y, gnss.heading, gnss.sigma) == (25.0, 17.0, 0.5, 1.2)


def test_inline_and_process_sensing_give_bitwise_the_same_faulty_data() -> None:
    events = (EventSpec(TimeTrigger(0.4), CameraFreeze("front", 0.4)),
              EventSpec(TimeTrigger(0.9), CameraBlackout("front", 0.3)),
              EventSpec(TimeTrigger(0.5), LidarOutage(0.5)),
              EventSpec(TimeTrigger(0.3), GnssJump((20.0, 0.0), 0.4)),
              EventSpec(TimeTrigger(1.2), GnssOutage(0.3)),
              EventSpec(TimeTrigger(1.3), SensorDelay("front", 0.2, 0.2)),
              EventSpec(TimeTrigger(1.5), CameraOcclusion("front", 0.5, Side.LEFT, 0.3)))
    inline, process = drive("inline", events=events), drive("process", events=events)
    assert len(inline) == len(process)
    for (at_a, a), (at_b, b) in zip(inline, process, strict=True):
        assert at_a == at_b and a.due == b.due
        assert [r.sensor for r in a.readings] == [r.sensor for r in b.readings]
        for ra, rb in zip(a.readings, b.readings, strict=True):
            assert_same(ra.frame, rb.frame)
            assert_same(ra.truth, rb.truth)
    # and the faults are in it: frozen, black, then occluded fronts; scans missing; fixes
    # off
    fronts = {round(c.t, 3): r.frame.rgb for _, c in inline for r in c.readings
              if isinstance(r.frame, CameraFrame) and r.sensor == "front"}
    for t, rgb in fronts.items():
        if 0.4 <= t < 0.8:  # the image delivered last before the freeze, held
            assert np.array_equal(rgb, fronts[0.3]), t
        elif 0.9 <= t < 1.2:
            assert not rgb.any(), t
        elif 1.5 <= t < 1.8:
            assert not rgb[:, :320].any() and rgb[:, 320:].any(), t
        else:
            assert (rgb.any() and not np.array_equal(rgb, fronts[0.3])) or t == 0.3, t
    scans = [round(c.t, 3) for _, c in inline if "lidar" in c.due.sensors]
    got = [round(c.t, 3) for _, c in inline for r in c.readings if r.sensor == "lidar"]
    assert sorted(set(scans) - set(got)) == [0.5, 0.6, 0.7, 0.8, 0.9]
    fixes = {round(c.t, 3): r.frame for _, c in inline for r in c.readings
             if isinstance(r.frame, GnssFix)}
    assert [t for t, f in fixes.items() if not f.valid] == [1.2, 1.3, 1.4]
    truth = {round(c.t, 3): r.frame for _, c in drive("inline", events=())
             for r in c.readings if isinstance(r.frame, GnssFix)}
    for t, f in fixes.items():
        jump = 20.0 if 0.3 <= t < 0.7 else 0.0
        assert not f.valid or (f.x, f.y) == (truth[t].x + jump, truth[t].y), t
