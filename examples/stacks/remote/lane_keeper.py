"""A stack in its own process that speaks only avsim's remote stack protocol: it imports
nothing of avsim's (docs/stack-protocol.md is all it knows), so the same program could be
written in any language with a MessagePack library.

It keeps the start lane and cruises at the driver's set speed, within the posted limits
and a comfortable lateral acceleration in the curves, on GNSS + odometry and the map's lane
centre lines it got in ``hello``:

- pose: dead reckoning on the odometry's speed and yaw rate, pulled towards each valid
  GNSS fix (x += K_FIX (x_fix - x), the same for y and the heading);
- steering: pure pursuit on the lane's centre line, lookahead L = max(L_MIN, T_LOOK v):
  delta = atan(2 l y_L / L_d^2) with the wheelbase l and the target (x_L, y_L) in the
  vehicle frame, L_d its distance;
- speed: v_target = min(set speed, the lowest limit and curve speed sqrt(A_LAT / |k|)
  within PREVIEW), accel = K_V (v_target - v) within [A_MIN, A_MAX].

It sees no other road user: it keeps no distance and brakes for nothing (a sensorless
proxy; a real stack reads the camera or LiDAR frames too).

Run: ``avsim run normal_driving --profile none --stack examples/stacks/remote/launch.py:make``.
"""

from __future__ import annotations

import math
import struct
import sys
from typing import Any, BinaryIO

import msgpack

NAME, VERSION = "lane-keeper", "1.0"
K_FIX = 0.2  # [-] the pull of a GNSS fix on the dead-reckoned pose, per fix
L_MIN = 6.0  # [m] the shortest lookahead
T_LOOK = 0.9  # [s] the lookahead's growth with speed
K_V = 0.8  # [1/s] speed error to acceleration
A_MIN, A_MAX = -4.0, 1.5  # [m/s^2]
A_LAT = 1.8  # [m/s^2] the lateral acceleration the curve speed allows
PREVIEW = 40.0  # [m] how far ahead limits and curves slow the target speed
SEARCH = 30  # [samples] the window around the last nearest sample, each way
HEADER = struct.Struct(">I")  # the length prefix: 4 bytes, unsigned, big-endian


def read_message(stream: BinaryIO) -> dict[str, Any] | None:
    """The next message, or None at the end of the input (avsim has gone)."""
    header = stream.read(HEADER.size)
    if len(header) < HEADER.size:
        return None
    (size,) = HEADER.unpack(header)
    message: dict[str, Any] = msgpack.unpackb(stream.read(size), raw=False)
    return message


def write_message(stream: BinaryIO, message: dict[str, Any]) -> None:
    body = msgpack.packb(message, use_bin_type=True)
    stream.write(HEADER.pack(len(body)) + body)
    stream.flush()


def doubles(data: bytes) -> list[float]:
    """Little-endian float64 bytes as numbers."""
    return list(struct.unpack(f"<{len(data) // 8}d", data))


def wrap(angle: float) -> float:
    return math.remainder(angle, math.tau)


class LaneKeeper:
    def __init__(self, hello: dict[str, Any]) -> None:
        road, vehicle = hello["map"], hello["vehicle"]
        lane = next(lane for lane in road["lanes"] if lane["index"] == hello["start_lane"])
        self.s, self.x, self.y = doubles(road["s"]), doubles(lane["x"]), doubles(lane["y"])
        self.heading = doubles(lane["heading"])
        self.limit = doubles(road["speed_limit"])
        self.step = road["length"] / max(1, road["count"] - 1)  # [m]
        self.wheelbase, self.max_steer = vehicle["wheelbase"], vehicle["max_steer"]
        self.set_speed = hello["set_speed"]
        self.pose: tuple[float, float, float] | None = None  # [m, m, rad] map frame
        self.speed = self.yaw_rate = 0.0  # [m/s], [rad/s]
        self.t = 0.0  # [s] of the pose
        self.near = 0  # the last nearest sample

    def on_frames(self, message: dict[str, Any]) -> None:
        odometry, fix = message["frames"].get("odometry"), message["frames"].get("gnss")
        if odometry is not None:
            self.dead_reckon(odometry["t"])
            self.speed, self.yaw_rate = odometry["speed"], odometry["yaw_rate"]
        if fix is not None and fix["valid"]:
            self.dead_reckon(fix["t"])
            if self.pose is None:
                self.pose = (fix["x"], fix["y"], fix["heading"])
            else:
                x, y, yaw = self.pose
                self.pose = (x + K_FIX * (fix["x"] - x), y + K_FIX * (fix["y"] - y),
                             wrap(yaw + K_FIX * wrap(fix["heading"] - yaw)))

    def dead_reckon(self, t: float) -> None:
        dt, self.t = t - self.t, t
        if self.pose is not None and dt > 0.0:
            x, y, yaw = self.pose
            self.pose = (x + self.speed * dt * math.cos(yaw),
                         y + self.speed * dt * math.sin(yaw), wrap(yaw + self.yaw_rate * dt))

    def nearest(self, x: float, y: float) -> int:
        lo, hi = max(0, self.near - SEARCH), min(len(self.s), self.near + SEARCH + 1)
        if self.near == 0:
            lo, hi = 0, len(self.s)  # the first search covers the whole lane
        self.near = min(range(lo, hi), key=lambda i: (self.x[i] - x) ** 2 + (self.y[i] - y) ** 2)
        return self.near

    def target_speed(self, i: int) -> float:
        target: float = self.set_speed
        for j in range(i, min(len(self.s) - 1, i + int(PREVIEW / self.step))):
            target = min(target, self.limit[j])
            k = abs(wrap(self.heading[j + 1] - self.heading[j])) / self.step  # [1/m]
            if k > 1e-6:
                target = min(target, math.sqrt(A_LAT / k))
        return target

    def tick(self) -> dict[str, Any]:
        if self.pose is None:  # no fix yet: stand still
            return {"type": "command", "steering_angle": 0.0, "accel": A_MIN}
        x, y, yaw = self.pose
        i = self.nearest(x, y)
        look = max(L_MIN, T_LOOK * self.speed)
        j = min(len(self.s) - 1, i + round(look / self.step))
        dx, dy = self.x[j] - x, self.y[j] - y
        ahead = math.cos(yaw) * dx + math.sin(yaw) * dy  # [m] vehicle frame
        left = -math.sin(yaw) * dx + math.cos(yaw) * dy
        steer = math.atan2(2.0 * self.wheelbase * left, ahead * ahead + left * left)
        steer = max(-self.max_steer, min(steer, self.max_steer))
        target = self.target_speed(i)
        accel = max(A_MIN, min(K_V * (target - self.speed), A_MAX))
        cross = -math.sin(self.heading[i]) * (x - self.x[i]) \
            + math.cos(self.heading[i]) * (y - self.y[i])
        return {"type": "command", "steering_angle": steer, "accel": accel,
                "channels": {"target_speed": target, "cross_track": cross}}


def main() -> int:
    stdin, stdout = sys.stdin.buffer, sys.stdout.buffer
    keeper: LaneKeeper | None = None
    while (message := read_message(stdin)) is not None:
        kind = message["type"]
        if kind == "hello":
            keeper = LaneKeeper(message)
            write_message(stdout, {"type": "ready", "name": NAME, "version": VERSION,
                                   "reads": ["gnss", "odometry"]})
        elif kind == "frames" and keeper is not None:
            keeper.on_frames(message)
        elif kind == "tick" and keeper is not None:
            write_message(stdout, keeper.tick())
        elif kind == "bye":
            break
    return 0


if __name__ == "__main__":
    sys.exit(main())
