"""The remote stack protocol's messages (`avsim.stack.wire`) and framing
(`avsim.stack.channel`), without a simulation: what avsim sends decodes to the map and
frames it came from, every key it sends is documented on docs/stack-protocol.md, and bad
replies, oversize messages, a silent or a closed peer are refused by kind."""

from __future__ import annotations

import math
import os
import re
from pathlib import Path
from typing import Any

import msgpack
import numpy as np
import pytest

from avsim.scenario.load import load_scenario
from avsim.stack import wire
from avsim.stack.channel import HEADER, Channel, ChannelError
from avsim.stack.context import StackContext
from world.frames import (
    CameraFrame,
    CameraInfo,
    DriverControls,
    GnssFix,
    GroundTruth,
    LidarInfo,
    LidarScan,
    Odometry,
    SensorKind,
    SensorMount,
    SensorSpec,
    TruthObject,
    VehicleInfo,
)
from world.map.road import build_road_map

DOC = (Path(__file__).resolve().parents[3] / "docs" / "stack-protocol.md").read_text()
DOCUMENTED = set(re.findall(r"`([a-z_]+)`", DOC))
MOUNT = SensorMount(1.5, 0.0, 1.4, pitch=0.05)
CAMERA = CameraInfo("front", 8, 6, 1.2, MOUNT)
LIDAR = LidarInfo((-0.2, 0.0, 0.2), 4, 80.0, MOUNT)


def _keys(data: Any) -> set[str]:
    """Every map key in `data`, nested (sensor and lane maps included)."""
    if isinstance(data, dict):
        return set(data) | set().union(*(_keys(v) for v in data.values()))
    if isinstance(data, list):
        return set().union(*(_keys(v) for v in data))
    return set()


def _context() -> StackContext:
    road = build_road_map(load_scenario("sudden_stop").world.road)
    sensors = (SensorSpec("front", SensorKind.CAMERA, 10.0, 0.1, CAMERA),
               SensorSpec("lidar", SensorKind.LIDAR, 10.0, 0.1, LIDAR),
               SensorSpec("gnss", SensorKind.GNSS, 10.0, 0.0),
               SensorSpec("odometry", SensorKind.ODOMETRY, 40.0, 0.0))
    return StackContext(road, VehicleInfo(4.8, 1.9, 2.8, 1.6, 1.4, 1.4, 1500.0, 0.32, 0.6),
                        sensors, 0, 13.9, 40.0, False, 21)


def _frames() -> dict[str, Any]:
    rng = np.random.default_rng(0)
    return {"front": CameraFrame(1.0, CAMERA, rng.integers(0, 255, (6, 8, 3), dtype=np.uint8)),
            "lidar": LidarScan(1.0, LIDAR, rng.normal(size=(5, 3)).astype(np.float32),
                               np.array([0, 1, 2, 1, 0], np.uint8),
                               np.array([0, 1, 2, 3, 3], np.uint16)),
            "gnss": GnssFix(1.0, 3.0, 4.0, 0.1, 0.05, 0.01),
            "odometry": Odometry(1.0, (40.0, 40.0, 41.0, 41.0), 0.32, 0.02, -0.01,
                                 driver=DriverControls(set_speed=12.0))}


def _over_the_wire(message: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = msgpack.unpackb(msgpack.packb(message, use_bin_type=True),
                                          raw=False)
    return out


def test_hello_carries_each_lane_sampled_every_metre_and_every_key_is_documented() -> None:
    ctx = _context()
    hello = _over_the_wire(wire.hello(ctx))
    road = hello["map"]
    s = np.frombuffer(road["s"], "<f8")
    assert road["count"] == len(s) == math.ceil(ctx.road.length) + 1
    assert np.allclose(np.diff(s), ctx.road.length / (len(s) - 1))
    assert [lane["index"] for lane in road["lanes"]] == [0, 1, -1]
    for lane in road["lanes"]:
        xy = np.column_stack([np.frombuffer(lane["x"], "<f8"), np.frombuffer(lane["y"], "<f8")])
        assert np.array_equal(xy, ctx.road.lane(lane["index"]).position(s, np.zeros_like(s)))
        assert np.array_equal(np.frombuffer(lane["width"], "<f8"),
                              ctx.road.lane(lane["index"]).width_at(s))
    assert np.array_equal(np.frombuffer(road["speed_limit"], "<f8"),
                          ctx.road.speed_limit_at(s))
    assert hello["sensors"][1]["lidar"]["elevations"] == [-0.2, 0.0, 0.2]
    assert hello["vehicle"]["wheelbase"] == 2.8 and hello["api"] == "1.1"
    assert _keys(hello) - DOCUMENTED == set()


def test_each_frame_decodes_to_the_arrays_it_came_from_and_its_keys_are_documented() -> None:
    frames = _frames()
    sent = _over_the_wire(wire.frames(1.0, frames, None))["frames"]
    camera, scan = frames["front"], frames["lidar"]
    assert isinstance(camera, CameraFrame) and isinstance(scan, LidarScan)
    rgb = np.frombuffer(sent["front"]["rgb"], np.uint8).reshape(sent["front"]["height"],
                                                                 sent["front"]["width"], 3)
    assert np.array_equal(rgb, camera.rgb)
    points = np.frombuffer(sent["lidar"]["points"], "<f4").reshape(sent["lidar"]["count"], 3)
    assert np.array_equal(points, scan.points)
    assert np.array_equal(np.frombuffer(sent["lidar"]["column"], "<u2"), scan.column)
    assert sent["odometry"]["speed"] == pytest.approx(41.0 * 0.32)
    assert sent["odometry"]["driver"]["set_speed"] == 12.0
    assert _keys(sent) - DOCUMENTED - set(frames) == set()
    only = wire.frames(1.0, frames, frozenset({"gnss"}))
    assert set(only["frames"]) == {"gnss"}  # a stack gets only the sensors it reads


def test_a_truth_frame_goes_over_the_wire_whole_and_its_keys_are_documented() -> None:
    truth = GroundTruth(2.0, 10.0, 1.0, 0.1, 12.0, 0.01, 0.02, (TruthObject(
        "lead", "car", 40.0, 1.5, 0.05, 11.0, 0.4, 4.77, 1.83, 1.46),))
    sent = _over_the_wire(wire.frames(2.0, {"truth": truth}, None))["frames"]["truth"]
    assert (sent["kind"], sent["speed"], sent["steering_angle"]) == ("truth", 12.0, 0.02)
    (lead,) = sent["objects"]
    assert (lead["id"], lead["vy"], lead["width"]) == ("lead", 0.4, 1.83)
    assert _keys({"truth": sent}) - DOCUMENTED - {"truth"} == set()


@pytest.mark.parametrize(("reply", "problem"), [
    ({"type": "ready"}, "expected 'command'"),
    ({"type": "command", "accel": 1.0}, "command.steering_angle: None is not a finite"),
    ({"type": "command", "steering_angle": 0.0, "accel": math.inf}, "command.accel: inf"),
    ({"type": "command", "steering_angle": 0.0, "accel": 1.0, "drive_torque": 5.0},
     "accel or the torques, not both"),
    ({"type": "command", "steering_angle": 0.0, "drive_torque": 5.0, "brake_torque": 5.0},
     "at most one of them > 0"),
    ({"type": "command", "steering_angle": 0.0, "drive_torque": -5.0, "brake_torque": 0.0},
     "must be >= 0"),
    ({"type": "command", "steering_angle": 0.0, "accel": 0.0, "hazard_lights": 1},
     "hazard_lights: not a boolean"),
])
def test_a_bad_command_is_refused_naming_its_field(reply: dict[str, Any], problem: str) -> None:
    with pytest.raises(wire.WireError, match=re.escape(problem)):
        wire.command(reply)


@pytest.mark.parametrize(("channels", "problem"), [
    ({"9lives": 1.0}, "is not a name"), ({"ok": "high"}, "is not a number"),
    ({f"c{i}": 0.0 for i in range(65)}, "at most 64 entries"),
])
def test_bad_channels_are_refused(channels: dict[str, Any], problem: str) -> None:
    with pytest.raises(wire.WireError, match=problem):
        wire.channels({"type": "command", "channels": channels})


def test_torques_are_taken_as_given_and_an_accel_left_to_drive_by_wire() -> None:
    torques = wire.command({"type": "command", "steering_angle": 0.1, "drive_torque": 300,
                            "brake_torque": 0, "hazard_lights": True})
    assert torques.torques is not None and torques.accel is None
    assert (torques.torques.drive_torque, torques.torques.hazard_lights) == (300.0, True)
    accel = wire.command({"type": "command", "steering_angle": 0.1, "accel": -2})
    assert (accel.accel, accel.torques) == (-2.0, None)


def _pipe_pair() -> tuple[Channel, int, int]:
    """A channel reading from a pipe whose write end is returned, and writing to one whose
    read end is returned."""
    into_r, into_w = os.pipe()
    out_r, out_w = os.pipe()
    return Channel(out_w, into_r, max_in=64), into_w, out_r


def test_the_channel_refuses_an_oversize_message_a_silent_peer_and_a_closed_one() -> None:
    channel, peer_w, peer_r = _pipe_pair()
    os.write(peer_w, HEADER.pack(65) + b"x")
    with pytest.raises(ChannelError, match="a message of 65 bytes") as oversize:
        channel.receive(1.0)
    assert oversize.value.kind == "garbage"
    with pytest.raises(ChannelError) as silent:
        channel.receive(0.01)  # nothing more comes
    assert silent.value.kind == "timeout"
    os.close(peer_w)
    with pytest.raises(ChannelError) as closed:
        channel.receive(1.0)
    assert closed.value.kind == "closed"
    os.close(peer_r)
    with pytest.raises(ChannelError) as gone:
        channel.send({"type": "bye"}, 1.0)
    assert gone.value.kind == "closed"


def test_a_peer_that_stops_reading_cannot_block_a_send_past_its_wait() -> None:
    channel, _, _ = _pipe_pair()  # nobody reads: the pipe fills (64 KiB) and stays full
    with pytest.raises(ChannelError) as full:
        channel.send({"type": "frames", "blob": b"\0" * (1 << 20)}, 0.05)
    assert full.value.kind == "timeout"


def test_a_message_round_trips_through_the_channel() -> None:
    channel, peer_w, peer_r = _pipe_pair()
    channel.send({"type": "tick", "t": 0.5, "dt": 0.025}, 1.0)
    header = os.read(peer_r, 4)
    body = os.read(peer_r, HEADER.unpack(header)[0])
    assert msgpack.unpackb(body) == {"type": "tick", "t": 0.5, "dt": 0.025}
    reply = msgpack.packb({"type": "command", "steering_angle": 0.0, "accel": 0.0})
    os.write(peer_w, HEADER.pack(len(reply)) + reply)
    assert channel.receive(1.0)["type"] == "command"
