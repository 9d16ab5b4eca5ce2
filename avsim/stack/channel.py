"""Length-prefixed MessagePack maps over a pair of pipes, every wait and size bounded
(`Channel`): the transport of the remote stack protocol (docs/stack-protocol.md).

A message on the wire is a 4-byte unsigned big-endian length N, then N bytes: one
MessagePack map whose string key ``type`` names the message. Writes and reads each wait at
most a timeout [s]: a peer that stops reading or answering cannot hang avsim. A peer that
closes its end, sends a length above the bound or bytes that are not such a map raises
`ChannelError`, one line saying which.
"""

from __future__ import annotations

import os
import select
import struct
import time
from collections.abc import Mapping
from typing import Any

import msgpack

HEADER = struct.Struct(">I")  # the length prefix: 4 bytes, unsigned, big-endian
MAX_TYPE = 32  # [characters] of a message's type


class ChannelError(Exception):
    """The channel failed: `kind` is 'closed' (the peer closed its end), 'timeout' (no
    progress within the wait) or 'garbage' (the bytes are not a message); the text says
    what, in one line."""

    def __init__(self, kind: str, problem: str) -> None:
        super().__init__(problem)
        self.kind = kind


class Channel:
    """Messages out on `write_fd`, in on `read_fd` (both made non-blocking; the channel
    does not own them). `max_in` [bytes]: the largest message accepted from the peer."""

    def __init__(self, write_fd: int, read_fd: int, max_in: int) -> None:
        self.write_fd, self.read_fd, self.max_in = write_fd, read_fd, max_in
        os.set_blocking(write_fd, False)
        os.set_blocking(read_fd, False)

    def send(self, message: Mapping[str, Any], timeout: float) -> None:
        """Write `message` whole within `timeout` [s]."""
        body = msgpack.packb(message, use_bin_type=True)
        view = memoryview(HEADER.pack(len(body)) + body)
        deadline = time.monotonic() + timeout
        while view:
            _wait(self.write_fd, deadline, write=True)
            try:
                done = os.write(self.write_fd, view)
            except BlockingIOError:
                continue
            except (BrokenPipeError, ConnectionResetError):
                raise ChannelError("closed", "it closed its input") from None
            view = view[done:]

    def receive(self, timeout: float) -> dict[str, Any]:
        """The next message, read whole within `timeout` [s]: a map with a string `type`."""
        deadline = time.monotonic() + timeout
        (size,) = HEADER.unpack(self._read(HEADER.size, deadline))
        if size > self.max_in:
            raise ChannelError("garbage", f"a message of {size} bytes (at most "
                               f"{self.max_in})")
        body = self._read(size, deadline)
        try:
            message = msgpack.unpackb(body, raw=False, strict_map_key=True)
        except (ValueError, msgpack.UnpackException) as exc:
            raise ChannelError("garbage", f"not MessagePack ({exc})") from None
        if not isinstance(message, dict) or not isinstance(message.get("type"), str):
            raise ChannelError("garbage", "not a map with a string 'type'")
        if len(message["type"]) > MAX_TYPE:
            raise ChannelError("garbage", "a message type longer than "
                               f"{MAX_TYPE} characters")
        return message

    def _read(self, size: int, deadline: float) -> bytes:
        """Exactly `size` bytes by `deadline` (`time.monotonic`)."""
        chunks: list[bytes] = []
        left = size
        while left:
            _wait(self.read_fd, deadline, write=False)
            try:
                chunk = os.read(self.read_fd, min(left, 1 << 20))
            except BlockingIOError:
                continue
            if not chunk:
                raise ChannelError("closed", "it closed its output")
            chunks.append(chunk)
            left -= len(chunk)
        return b"".join(chunks)


def _wait(fd: int, deadline: float, write: bool) -> None:
    """Until `fd` is ready to write (or read), or `ChannelError` 'timeout' at `deadline`."""
    remaining = deadline - time.monotonic()
    if remaining > 0.0:
        ready = select.select([], [fd], [], remaining) if write \
            else select.select([fd], [], [], remaining)
        if ready[0] or ready[1]:
            return
    raise ChannelError("timeout", "no answer in time")
