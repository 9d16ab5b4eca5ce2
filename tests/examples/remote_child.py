"""A remote stack that breaks the protocol on purpose, after `AFTER` ticks of driving
straight on: ``remote_child.py MODE`` with MODE one of

- ``crash``: raises (a traceback on stderr, exit status 1);
- ``hang``: stops answering (sleeps);
- ``huge``: announces a message longer than avsim accepts;
- ``notmap``: sends a MessagePack number, not a map;
- ``nan``: a command whose steering angle is NaN;
- ``silent``: never answers ``hello``.

It imports nothing of avsim's, as a remote stack would not.
"""

from __future__ import annotations

import struct
import sys
import time
from typing import Any

import msgpack

AFTER = 10  # [ticks] of good answers before the trouble
HEADER = struct.Struct(">I")


def send(message: Any) -> None:
    body = msgpack.packb(message, use_bin_type=True)
    sys.stdout.buffer.write(HEADER.pack(len(body)) + body)
    sys.stdout.buffer.flush()


def misbehave(mode: str) -> None:
    if mode == "crash":
        raise RuntimeError("boom: the remote stack's own bug")
    if mode == "hang":
        time.sleep(3600)
    if mode == "huge":
        sys.stdout.buffer.write(HEADER.pack(0xFFFFFFF0) + b"junk")
        sys.stdout.buffer.flush()
    if mode == "notmap":
        send(42)
    if mode == "nan":
        send({"type": "command", "steering_angle": float("nan"), "accel": 0.0})


def main(mode: str) -> None:
    stdin, ticks = sys.stdin.buffer, 0
    while len(header := stdin.read(HEADER.size)) == HEADER.size:
        message = msgpack.unpackb(stdin.read(HEADER.unpack(header)[0]), raw=False)
        if message["type"] == "hello":
            if mode == "silent":
                time.sleep(3600)
            send({"type": "ready", "name": mode, "version": "0", "reads": ["odometry"]})
        elif message["type"] == "tick":
            ticks += 1
            if ticks > AFTER:
                misbehave(mode)
                time.sleep(3600)  # the trouble was sent: wait to be ended
            send({"type": "command", "steering_angle": 0.0, "accel": 0.0})
        elif message["type"] == "bye":
            return


if __name__ == "__main__":
    main(sys.argv[1])
