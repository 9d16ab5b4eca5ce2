"""The remote stack protocol's messages as plain data (docs/stack-protocol.md): what avsim
sends (`hello`, `frames`, `tick`, `bye`) and what it accepts back (`ready`, `command`).

Plain data is what MessagePack carries: maps with string keys, numbers, booleans, nil,
strings, lists and byte strings. Arrays travel as byte strings, little-endian, row-major,
their element type and shape stated beside them. Units are SI, frames as `world.frames`
says (map: x east, y north, yaw counter-clockwise from +x; vehicle: x forward, y left).
"""

from __future__ import annotations

import math
import re
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from avsim.stack.context import API_VERSION, StackContext
from control.command import VehicleCommand
from world.frames import (
    CameraFrame,
    CameraInfo,
    Frame,
    Frames,
    GnssFix,
    GroundTruth,
    LidarInfo,
    LidarScan,
    Odometry,
    SensorSpec,
)
from world.hdmap import Lane, RoadMap

MAP_STEP = 1.0  # [m] the lanes' sampling step along the route
MAX_MAP_SAMPLES = 20_000  # [-] per lane at most: a longer route is sampled more coarsely
MAX_CHANNELS = 64  # [-] a command's named channels, at most
MAX_READS = 64  # [-] sensor names a `ready` may list
MAX_TEXT = 200  # [characters] of a name, a version or a sensor name in `ready`
CHANNEL_NAME = re.compile(r"^[A-Za-z]\w{0,63}$")


class WireError(Exception):
    """A message from the stack that breaks the protocol (one line: which field, what)."""


def _f64(values: Any) -> bytes:
    """`values` as little-endian float64 bytes."""
    return np.ascontiguousarray(values, dtype="<f8").tobytes()


def _sensor(spec: SensorSpec) -> dict[str, Any]:
    """A sensor as plain data: name, kind, rate [Hz], latency [s], calibration."""
    out: dict[str, Any] = {"name": spec.name, "kind": spec.kind.value, "rate": spec.rate,
                           "latency": spec.latency}
    if isinstance(spec.info, CameraInfo):
        out["camera"] = {"width": spec.info.width, "height": spec.info.height,
                         "fov_x": spec.info.fov_x, "near": spec.info.near,
                         "far": spec.info.far, "mount": asdict(spec.info.mount)}
    elif isinstance(spec.info, LidarInfo):
        out["lidar"] = {"elevations": list(spec.info.elevations),
                        "azimuth_steps": spec.info.azimuth_steps,
                        "max_range": spec.info.max_range,
                        "range_sigma": spec.info.range_sigma, "dropout": spec.info.dropout,
                        "mount": asdict(spec.info.mount)}
    return out


def _lane(lane: Lane, s: np.ndarray) -> dict[str, Any]:
    """One lane's centre line sampled at stations `s` [m]."""
    xy = lane.position(s, np.zeros_like(s))
    return {"index": lane.index, "direction": lane.direction,
            "x": _f64(xy[:, 0]), "y": _f64(xy[:, 1]), "heading": _f64(lane.heading_at(s)),
            "width": _f64(lane.width_at(s)),
            "exists": np.asarray(lane.exists_at(s), dtype=np.uint8).tobytes()}


def road_map(road: RoadMap) -> dict[str, Any]:
    """The map's lanes sampled along the route (every `MAP_STEP`, at most
    `MAX_MAP_SAMPLES` per lane, both ends included) and its posted limits."""
    count = min(MAX_MAP_SAMPLES, math.ceil(road.length / MAP_STEP) + 1)
    s = np.linspace(0.0, road.length, max(count, 2))
    return {"length": road.length, "count": len(s), "s": _f64(s),
            "lanes": [_lane(lane, s) for lane in (*road.lanes, *road.oncoming)],
            "speed_limit": _f64(road.speed_limit_at(s)),
            "speed_limits": [{"s": p.s, "limit": p.limit} for p in road.speed_limits]}


def hello(ctx: StackContext) -> dict[str, Any]:
    """The first message: the API version and everything the stack is built with."""
    return {"type": "hello", "api": API_VERSION, "vehicle": asdict(ctx.vehicle),
            "sensors": [_sensor(s) for s in ctx.sensors], "start_lane": ctx.start_lane,
            "set_speed": ctx.set_speed, "max_speed": ctx.max_speed,
            "overtake": ctx.overtake, "seed": ctx.seed, "map": road_map(ctx.road)}


def _odometry(frame: Odometry) -> dict[str, Any]:
    driver = frame.driver
    return {"kind": "odometry", "t": frame.t, "wheel_speeds": list(frame.wheel_speeds),
            "wheel_radius": frame.wheel_radius, "speed": frame.speed,
            "yaw_rate": frame.yaw_rate, "steering_angle": frame.steering_angle,
            "accelerator_pedal": frame.accelerator_pedal, "engaged": frame.engaged,
            "driver": {"set_speed": driver.set_speed, "lane_request": driver.lane_request,
                       "brake": driver.brake, "activations": driver.activations}}


def _truth(frame: GroundTruth) -> dict[str, Any]:
    return {"kind": "truth", "t": frame.t, "x": frame.x, "y": frame.y,
            "heading": frame.heading, "speed": frame.speed, "yaw_rate": frame.yaw_rate,
            "steering_angle": frame.steering_angle,
            "objects": [{"id": o.id, "kind": o.kind, "x": o.x, "y": o.y, "yaw": o.yaw,
                         "vx": o.vx, "vy": o.vy, "length": o.length, "width": o.width,
                         "height": o.height} for o in frame.objects]}


def frame_data(frame: Frame) -> dict[str, Any]:
    """One sensor's frame as plain data (its `kind` says which)."""
    if isinstance(frame, Odometry):
        return _odometry(frame)
    if isinstance(frame, GnssFix):
        return {"kind": "gnss", "t": frame.t, "x": frame.x, "y": frame.y,
                "heading": frame.heading, "sigma": frame.sigma,
                "heading_sigma": frame.heading_sigma, "valid": frame.valid}
    if isinstance(frame, CameraFrame):
        height, width = frame.rgb.shape[:2]
        return {"kind": "camera", "t": frame.t, "width": width, "height": height,
                "rgb": np.ascontiguousarray(frame.rgb, dtype=np.uint8).tobytes()}
    if isinstance(frame, GroundTruth):
        return _truth(frame)
    scan: LidarScan = frame
    return {"kind": "lidar", "t": scan.t, "count": len(scan.points),
            "points": np.ascontiguousarray(scan.points, dtype="<f4").tobytes(),
            "ring": np.ascontiguousarray(scan.ring, dtype=np.uint8).tobytes(),
            "column": np.ascontiguousarray(scan.column, dtype="<u2").tobytes()}


def frames(t: float, delivered: Frames, reads: frozenset[str] | None) -> dict[str, Any]:
    """One delivery captured at `t` [s]: the frames of the sensors the stack reads."""
    return {"type": "frames", "t": t,
            "frames": {name: frame_data(f) for name, f in delivered.items()
                       if reads is None or name in reads}}


def _number(message: dict[str, Any], key: str, default: float | None = None) -> float:
    value = message.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int | float) \
            or not math.isfinite(value):
        raise WireError(f"{message.get('type')}.{key}: {value!r} is not a finite number")
    return float(value)


def _text(message: dict[str, Any], key: str) -> str:
    value = message.get(key, "")
    if not isinstance(value, str) or len(value) > MAX_TEXT:
        raise WireError(f"ready.{key}: not a string of at most {MAX_TEXT} characters")
    return value


def ready(message: dict[str, Any]) -> tuple[str, str, frozenset[str] | None]:
    """The stack's name, version and the sensors it reads (None: all) from `ready`."""
    if message["type"] != "ready":
        raise WireError(f"expected 'ready', got {message['type']!r}")
    reads = message.get("reads")
    if reads is not None and (not isinstance(reads, list) or len(reads) > MAX_READS or not all(
            isinstance(r, str) and len(r) <= MAX_TEXT for r in reads)):
        raise WireError(f"ready.reads: not nil or a list of at most {MAX_READS} names")
    return _text(message, "name"), _text(message, "version"), \
        None if reads is None else frozenset(reads)


def channels(message: dict[str, Any]) -> dict[str, float]:
    """A command's named channels, checked."""
    given = message.get("channels", {})
    if not isinstance(given, dict) or len(given) > MAX_CHANNELS:
        raise WireError(f"command.channels: not a map of at most {MAX_CHANNELS} entries")
    out: dict[str, float] = {}
    for name in given:
        if not isinstance(name, str) or not CHANNEL_NAME.match(name):
            raise WireError(f"command.channels: {name!r} is not a name (a letter, then "
                            "letters, digits or _, 64 at most)")
        value = given[name]
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise WireError(f"command.channels.{name}: {value!r} is not a number")
        out[name] = float(value)
    return out


@dataclass(frozen=True, slots=True)
class Reply:
    """A `command` message, checked: the steering angle, and either an acceleration (the
    torques then made by wire, `avsim.stack.drive_by_wire`) or the torques' command."""

    steering_angle: float  # [rad] road-wheel angle, left +
    accel: float | None  # [m/s^2] the acceleration asked for; None: `torques` holds them
    torques: VehicleCommand | None  # the command of torques; None: `accel` is given
    hazard_lights: bool


def command(message: dict[str, Any]) -> Reply:
    """The checked reply to a `tick`."""
    if message["type"] != "command":
        raise WireError(f"expected 'command', got {message['type']!r}")
    steering = _number(message, "steering_angle")
    hazard = message.get("hazard_lights", False)
    if not isinstance(hazard, bool):
        raise WireError("command.hazard_lights: not a boolean")
    if "accel" in message:
        if "drive_torque" in message or "brake_torque" in message:
            raise WireError("command: give accel or the torques, not both")
        return Reply(steering, _number(message, "accel"), None, hazard)
    drive, brake = _number(message, "drive_torque"), _number(message, "brake_torque")
    if drive < 0.0 or brake < 0.0 or (drive > 0.0 and brake > 0.0):
        raise WireError("command: the torques must be >= 0, at most one of them > 0")
    return Reply(steering, None, VehicleCommand(
        steering, drive, brake, _number(message, "accel_request", 0.0), hazard), hazard)
