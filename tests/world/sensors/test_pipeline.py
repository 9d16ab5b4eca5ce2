"""Sensing pipelines: inline and in a worker process give bitwise the same data, camera
frames and LiDAR scans one sensor period late, GNSS and odometry at once; worker failures
surface as errors, not hangs."""

from __future__ import annotations

import itertools
import time
from dataclasses import replace

import numpy as np
import pytest

from avsim.scenario.load import load_scenario
from world.core.rates import CONTROL_RATE, FRAME_LATENCY, PHYSICS_RATE
from world.frames import CameraFrame, GnssFix, LidarScan, Odometry
from world.sensors.faults import FaultySensing
from world.sensors.frame_slots import SLOTS, shared_dir
from world.sensors.lidar import LidarTruth
from world.sensors.pipeline import (
    Capture,
    InlineSensing,
    ProcessSensing,
    Sensing,
    SensingError,
    SensingWorker,
    render_threads,
)
from world.sensors.schedule import SensorSchedule
from world.sensors.setup import Profile, sensor_setup, sensor_timings
from world.spec import EventSpec
from world.world import World

LATE = round(FRAME_LATENCY * PHYSICS_RATE)  # [steps]


def drive(mode: str, seconds: float = 2.0,
          events: tuple[EventSpec, ...] | None = None) -> list[tuple[int, Capture]]:
    """(delivery step, capture) of a car accelerating on normal_driving for `seconds`, the
    pipeline asked at every control tick as the sensor loop asks it; with `events` (sensor
    faults), those are the scenario's events and the pipeline applies them
    (`world.sensors.faults.FaultySensing`, as the sensor loop does)."""
    spec = load_scenario("normal_driving").world
    if events is not None:
        spec = replace(spec, events=events)
    setup = sensor_setup(Profile.DEFAULT)
    world = World(spec, setup, cameras=mode == "inline")
    sensing: Sensing = InlineSensing(world) if mode == "inline" \
        else ProcessSensing(world, setup)
    if events is not None:
        sensing = FaultySensing(sensing, lambda: world.sensor_faults)
    schedule = SensorSchedule(sensor_timings(setup), CONTROL_RATE)
    out = []
    try:
        world.ego.apply(0.0, 1500.0 * 2.0 * 0.33, 0.0)
        for _ in range(round(seconds * PHYSICS_RATE)):
            world.step()
            step = world.clock.step
            if step % CONTROL_RATE.every:
                continue
            arrived = sensing.collect(step)
            for due in schedule.due(step):
                sensing.submit(due)
            out += [(step, c) for c in (*arrived, *sensing.collect(step))]
    finally:
        sensing.close()
        world.close()
    return out


def assert_same(a: object, b: object) -> None:
    """Two frames (or truths) bitwise equal."""
    assert type(a) is type(b)
    if isinstance(a, CameraFrame) and isinstance(b, CameraFrame):
        assert a.t == b.t and a.info == b.info and np.array_equal(a.rgb, b.rgb)
    elif isinstance(a, LidarScan) and isinstance(b, LidarScan):
        assert a.t == b.t and a.info == b.info
        assert np.array_equal(a.points, b.points) and np.array_equal(a.ring, b.ring)
        assert np.array_equal(a.column, b.column)
    elif isinstance(a, LidarTruth) and isinstance(b, LidarTruth):
        assert np.array_equal(a.actor, b.actor)
    else:
        assert a == b


def test_inline_and_process_sensing_are_bitwise_equal() -> None:
    inline, process = drive("inline"), drive("process")
    assert len(inline) == len(process)
    for (at_a, a), (at_b, b) in zip(inline, process, strict=True):
        assert at_a == at_b and a.due == b.due and a.t == b.t
        assert [r.sensor for r in a.readings] == [r.sensor for r in b.readings] \
            == list(a.due.sensors)
        for ra, rb in zip(a.readings, b.readings, strict=True):
            assert_same(ra.frame, rb.frame)
            assert_same(ra.truth, rb.truth)
            assert ra.frame.t == a.t  # every frame is stamped with its capture time
    frames = [(at, c) for at, c in inline if c.due.deliver > c.step]
    at_once = [(at, c) for at, c in inline if c.due.deliver == c.step]
    # cameras and LiDAR at 10 Hz over 2 s, the last one still pending, one period late
    assert len(frames) == 19
    assert all(at == c.step + LATE for at, c in frames)
    names = [c.due.sensors for _, c in frames]
    # the sides at 2 Hz: captured at t = 0.5, 1.0, 1.5 and 2.0 (still pending at the end)
    assert names.count(("front", "left", "right", "lidar")) == 3
    assert names.count(("front", "lidar")) == 16
    for _, c in frames:
        assert isinstance(c.readings[0].frame, CameraFrame)
        assert isinstance(c.readings[-1].frame, LidarScan)
        assert isinstance(c.readings[-1].truth, LidarTruth)
        assert all(r.truth is None for r in c.readings[:-1])
    # GNSS with odometry at 10 Hz, odometry alone at the other control ticks, at once
    assert all(at == c.step for at, c in at_once)
    assert [c.due.sensors for _, c in at_once].count(("gnss", "odometry")) == 20
    assert [c.due.sensors for _, c in at_once].count(("odometry",)) == 60
    for _, c in at_once:
        assert isinstance(c.readings[-1].frame, Odometry)
        if len(c.readings) == 2:
            assert isinstance(c.readings[0].frame, GnssFix)
    # in a tick, the frames captured earlier come before those captured at once
    ticks = [at for at, _ in inline]
    assert ticks == sorted(ticks)
    for (at, c), (at_next, c_next) in itertools.pairwise(inline):
        if at == at_next:
            assert c.due.deliver > c.step and c_next.due.deliver == c_next.step


def test_a_capture_must_be_submitted_at_its_step() -> None:
    world = World(load_scenario("normal_driving").world)  # no profile: GNSS and odometry only
    sensing = InlineSensing(world)
    schedule = SensorSchedule(sensor_timings(None), CONTROL_RATE)
    try:
        assert sensing.renderer is None
        (due,) = schedule.due(0)
        world.step()
        with pytest.raises(ValueError, match="submitted at 1"):
            sensing.submit(due)
        assert sensing.collect(0) == ()
    finally:
        world.close()


def test_a_failing_worker_raises(monkeypatch: pytest.MonkeyPatch) -> None:
    spec = load_scenario("normal_driving").world
    setup = sensor_setup(Profile.DEFAULT)
    world = World(spec, setup, cameras=False)
    sensing = ProcessSensing(world, setup)
    try:
        monkeypatch.setattr(world, "snapshot", lambda: "not a snapshot")  # a broken request
        for due in SensorSchedule(sensor_timings(setup), CONTROL_RATE).due(0):
            sensing.submit(due)
        assert [c.due.sensors for c in sensing.collect(0)] == [("gnss", "odometry")]
        with pytest.raises(SensingError, match="sensing worker failed"):
            sensing.collect(LATE)
    finally:
        sensing.close()
        world.close()


def test_process_sensing_needs_a_world_without_cameras() -> None:
    setup = sensor_setup(Profile.FAST)
    world = World(load_scenario("normal_driving").world, setup, lidar=False)
    try:
        with pytest.raises(ValueError, match="without cameras"):
            ProcessSensing(world, setup)
    finally:
        world.close()


def held_captures(mode: str, captures: int) -> list[Capture]:
    """`captures` front-camera captures, one every control tick, none collected until the
    last was submitted: more requests unanswered than the worker has image slots."""
    spec = load_scenario("normal_driving").world
    setup = sensor_setup(Profile.FAST)
    world = World(spec, setup, cameras=mode == "inline", lidar=False)
    sensing = InlineSensing(world) if mode == "inline" else ProcessSensing(world, setup)
    schedule = SensorSchedule(sensor_timings(setup), CONTROL_RATE)
    front = next(due for due in schedule.due(0) if "front" in due.sensors)
    try:
        world.ego.apply(0.0, 1500.0 * 2.0 * 0.33, 0.0)
        for _ in range(captures):
            for _ in range(CONTROL_RATE.every):
                world.step()
            step = world.clock.step
            sensing.submit(replace(front, step=step, deliver=step + LATE, sensors=("front",)))
        time.sleep(2.0)  # let the worker answer all it was sent before any is read
        return list(sensing.collect(world.clock.step + LATE))
    finally:
        sensing.close()
        world.close()


def test_frames_survive_more_requests_in_flight_than_image_slots() -> None:
    captures = 3 * SLOTS + 1
    inline, process = held_captures("inline", captures), held_captures("process", captures)
    assert len(inline) == len(process) == captures
    for a, b in zip(inline, process, strict=True):
        assert a.due == b.due
        assert_same(a.readings[0].frame, b.readings[0].frame)
    # the car moved: the images differ from one capture to the next (a reused slot would
    # show up as two equal images or one from another capture)
    images = [c.readings[0].frame for c in process]
    assert all(isinstance(f, CameraFrame) for f in images)
    assert not any(np.array_equal(f.rgb, g.rgb)  # type: ignore[union-attr]
                   for f, g in itertools.pairwise(images))


def test_a_worker_started_first_serves_its_world_and_leaves_no_file() -> None:
    """A `SensingWorker` starts before the world is built; its image slot file is gone once
    both processes have mapped it, so nothing is left in shared memory whatever happens."""
    setup = sensor_setup(Profile.FAST)
    spec = load_scenario("normal_driving").world
    worker = SensingWorker(spec, setup)
    path = worker.slots.path
    assert path.parent == shared_dir() and path.name.startswith("avsim-frames-")
    assert path.exists()  # until the worker says it is ready
    world = World(spec, setup, cameras=False, lidar=False)
    sensing = ProcessSensing(world, setup, worker=worker)
    try:
        assert not path.exists()
        due = next(d for d in SensorSchedule(sensor_timings(setup), CONTROL_RATE).due(0)
                   if "front" in d.sensors)
        sensing.submit(replace(due, sensors=("front",)))
        (capture,) = sensing.collect(due.deliver)
        frame = capture.readings[0].frame
        assert isinstance(frame, CameraFrame) and frame.rgb.shape == (480, 640, 3)
        assert frame.rgb.std() > 10.0  # a picture, not an empty slot
        other = World(load_scenario("traffic_jam").world, setup, cameras=False, lidar=False)
        try:  # the worker mirrors another scenario's world: refused
            with pytest.raises(ValueError, match="another world"):
                ProcessSensing(other, setup, worker=worker)
        finally:
            other.close()
    finally:
        sensing.close()
        world.close()


@pytest.mark.parametrize(("profile", "threads"), [
    (Profile.FAST, 1), (Profile.DEFAULT, 1), (Profile.PAPER, 0)])
def test_light_cameras_render_on_one_thread(profile: Profile, threads: int) -> None:
    """The worker renders on one llvmpipe thread where the main process is the bottleneck
    (640x480 front), on every core where the worker is (three 1280x960 cameras)."""
    assert render_threads(sensor_setup(profile)) == threads
