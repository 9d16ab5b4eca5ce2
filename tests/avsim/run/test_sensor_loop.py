"""The sensor loop calls the stack in a fixed order within a control tick (the camera / LiDAR
capture due now, then GNSS if due, then odometry), keeps every `record_every`-th frame of
each sensor in the recording, and alters only the stack's frames with a frame hook."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from avsim.run.sensor_loop import SensorLoop
from avsim.scenario.load import load_scenario
from perception.messages import EgoState, PerceptionReport
from world.core.rates import CONTROL_RATE, PHYSICS_RATE
from world.frames import CameraFrame, Frame, Frames, GnssFix, LidarScan, Odometry
from world.sensors.setup import Profile, sensor_setup
from world.world import World

KIND = {CameraFrame: "camera", LidarScan: "lidar", GnssFix: "gnss", Odometry: "odometry"}


def _sensor_of(frame: Frame) -> str:
    """The sensor a frame came from, by its own data: a camera's name, else its kind."""
    return frame.info.name if isinstance(frame, CameraFrame) else KIND[type(frame)]


class FakeStack:
    """Writes down what it is handed; 'perceives' camera and LiDAR deliveries. It reads
    the front camera, the LiDAR, GNSS and odometry (as the stack does), or `reads`."""

    def __init__(self, reads: frozenset[str] = frozenset({"front", "lidar", "gnss",
                                                           "odometry"})) -> None:
        self.reads = reads
        self.calls: list[tuple[int, float, tuple[str, ...]]] = []  # (step, t, frame kinds)
        self.brightest: list[int] = []  # the brightest pixel of each camera frame
        self.names: list[tuple[str, ...]] = []  # the sensor names of each delivery
        self.step = 0

    def on_frames(self, t: float, frames: Frames) -> PerceptionReport | None:
        self.calls.append((self.step, t, tuple(KIND[type(f)] for f in frames.values())))
        self.names.append(tuple((name, _sensor_of(f)) for name, f in frames.items()))
        images = [f for f in frames.values() if isinstance(f, CameraFrame)]
        self.brightest += [int(f.rgb.max()) for f in images]
        if not images:
            return None
        pose = EgoState(t=t, x=0.0, y=0.0, heading=0.0, speed=0.0, yaw_rate=0.0,
                        steering_angle=0.0, position_sigma=0.0)
        return PerceptionReport(t, pose)


class FakeRecorder:
    def __init__(self) -> None:
        self.images: list[tuple[float, str, int]] = []  # (t, camera, brightest pixel)
        self.scans: list[float] = []

    def log_camera_image(self, t: float, name: str, rgb: np.ndarray, *_: Any,
                         **__: Any) -> None:
        self.images.append((t, name, int(rgb.max())))

    def log_lidar(self, t: float, *_: Any) -> None:
        self.scans.append(t)


def black(frame: CameraFrame) -> CameraFrame:
    return CameraFrame(frame.t, frame.info, np.zeros_like(frame.rgb))


def drive(stack: FakeStack, recorder: FakeRecorder | None) -> None:
    """1.1 s of normal_driving's first instants with the `default` profile, inline."""
    world = World(load_scenario("normal_driving").world, sensor_setup(Profile.DEFAULT))
    sensors = SensorLoop(world, sensor_setup(Profile.DEFAULT), stack, "inline",  # type: ignore[arg-type]
                         recorder, black)  # type: ignore[arg-type]
    try:
        while world.clock.step <= round(1.1 * PHYSICS_RATE):
            stack.step = world.clock.step
            sensors.tick()
            for _ in range(CONTROL_RATE.every):
                world.step()
    finally:
        sensors.close()
        world.close()


@pytest.fixture(scope="module")
def loop() -> tuple[FakeStack, FakeRecorder]:
    stack, recorder = FakeStack(), FakeRecorder()
    drive(stack, recorder)
    return stack, recorder


def test_calls_into_the_stack_within_a_tick(loop: tuple[FakeStack, FakeRecorder]) -> None:
    stack, _ = loop
    rows = {(step, t, kinds) for step, t, kinds in stack.calls}
    cameras_lidar = ("camera", "camera", "camera", "lidar")
    expected_first = [
        (0, 0.0, ("gnss", "odometry")),
        (6, 0.025, ("odometry",)),
        (12, 0.05, ("odometry",)),
        (18, 0.075, ("odometry",)),
        (24, 0.0, cameras_lidar),  # captured at 0, delivered 0.1 s later, first
        (24, 0.1, ("gnss", "odometry")),
        (30, 0.125, ("odometry",)),
        (48, 0.1, ("camera", "lidar")),
        (48, 0.2, ("gnss", "odometry")),
    ]
    assert stack.calls[:6] == expected_first[:6]
    assert set(expected_first) <= rows
    assert (144, 0.5, ("camera", "lidar")) in rows  # the sides at 2 Hz, but captured only
    #   for the recording (every 4th: t = 0, 2, ...): the stack does not read them
    ticks = round(1.1 * PHYSICS_RATE) // CONTROL_RATE.every + 1
    assert [s for s, _, k in stack.calls if k[-1] == "odometry"] == \
        [CONTROL_RATE.every * i for i in range(ticks)]  # odometry at every tick, once
    assert sum(k[0] == "gnss" for _, _, k in stack.calls) == 12  # 10 Hz, t = 0 .. 1.1 s
    assert sum(k[0] == "camera" for _, _, k in stack.calls) == 11  # t = 0 .. 1.0 s


def test_recording_keeps_every_nth_frame_of_each_sensor(
        loop: tuple[FakeStack, FakeRecorder]) -> None:
    _, recorder = loop
    # front every 5th of 10 Hz, sides every 4th of 2 Hz, LiDAR every 10th of 10 Hz; the
    # frames captured up to 1.0 s have been delivered
    assert [(t, name) for t, name, _ in recorder.images] == [
        (0.0, "front"), (0.0, "left"), (0.0, "right"), (0.5, "front"), (1.0, "front")]
    assert recorder.scans == [0.0, 1.0]


def test_the_hook_alters_the_stacks_frames_only(loop: tuple[FakeStack, FakeRecorder]) -> None:
    stack, recorder = loop
    assert stack.brightest and set(stack.brightest) == {0}
    assert all(brightest > 100 for _, _, brightest in recorder.images)


@pytest.mark.parametrize(("reads", "cameras"), [
    (frozenset({"front", "lidar", "gnss", "odometry"}), {("camera",)}),
    (frozenset({"front", "left", "lidar", "gnss", "odometry"}),
     {("camera",), ("camera", "camera")}),
])
def test_without_a_recording_a_camera_renders_only_if_the_stack_reads_it(
        reads: frozenset[str], cameras: set[tuple[str, ...]]) -> None:
    stack = FakeStack(reads)
    drive(stack, None)
    delivered = [tuple(k for k in kinds if k == "camera") for _, _, kinds in stack.calls
                 if "lidar" in kinds]
    assert len(delivered) == 11  # t = 0 .. 1.0 s at 10 Hz
    assert set(delivered) == cameras
    if len(cameras) == 2:  # the left camera at its 2 Hz: t = 0, 0.5 and 1.0 s
        assert delivered.count(("camera", "camera")) == 3


def test_a_delivery_names_each_frame_by_its_sensor(loop: tuple[FakeStack, FakeRecorder]) -> None:
    """The stack looks frames up by sensor name: each name is its frame's sensor."""
    stack, _ = loop
    pairs = [pair for delivery in stack.names for pair in delivery]
    assert pairs and all(name == sensor for name, sensor in pairs)
    assert {name for name, _ in pairs} >= {"front", "lidar", "gnss", "odometry"}
