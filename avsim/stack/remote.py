"""A whole stack in its own process, spoken to by the remote stack protocol
(docs/stack-protocol.md): `remote(ctx, command)` starts it, `RemoteStack` drives it.

avsim starts the stack's command line as a child process and exchanges length-prefixed
MessagePack maps with it over the child's stdin and stdout (`avsim.stack.channel`):
`hello` -> `ready` once, then per delivery `frames` (no reply), per control tick `tick` ->
`command`, and `bye` at the end. Everything is bounded: a reply's size (`MAX_REPLY`) and its
wait (`timeout` [s] per reply, `start_timeout` [s] for `ready`), the child's stderr kept as
its last `STDERR_TAIL` bytes. A child that dies, hangs or answers garbage raises
`RemoteStackError` (the run then ends with verdict error) naming its exit status and the
tail of its stderr. The child is reaped when the run closes the stack (`close`), and, as a
backstop, when the stack is garbage collected or the interpreter exits.

A user names the command in a factory of their own, the stack's one-line module::

    from avsim.stack.remote import remote

    def make(ctx):
        return remote(ctx, ["./my_stack", "--fast"])
"""

from __future__ import annotations

import os
import signal
import subprocess
import threading
import weakref
from collections.abc import Mapping, Sequence
from contextlib import suppress
from pathlib import Path
from typing import Any

from avsim.stack import wire
from avsim.stack.by_wire import drive_by_wire
from avsim.stack.channel import Channel, ChannelError
from avsim.stack.context import StackContext
from control.command import StackStep, VehicleCommand
from perception.messages import PerceptionReport
from world.frames import Frames, Odometry

MAX_REPLY = 1 << 20  # [bytes] the largest message accepted from the stack
STDERR_TAIL = 4096  # [bytes] of the child's stderr kept for the error message
TIMEOUT = 10.0  # [s] default wait for a reply (and for a message to be taken)
START_TIMEOUT = 30.0  # [s] default wait for `ready` (the child starts, loads, answers)
GRACE = 2.0  # [s] the child's time to exit after `bye` (or SIGTERM) before it is killed
MAX_ARGS = 256  # [-] words of the command line, at most


class RemoteStackError(Exception):
    """The stack's process failed: it exited, hung, or broke the protocol."""


class _StderrTail:
    """The last `STDERR_TAIL` bytes the child wrote to stderr, read by a daemon thread."""

    def __init__(self, fd: int) -> None:
        self._fd, self._tail = os.dup(fd), bytearray()  # its own descriptor, closed by the
        #   thread at the end of the stream (the process's pipe is closed when reaped)
        self._thread = threading.Thread(target=self._drain, name="remote-stack-stderr",
                                         daemon=True)
        self._thread.start()

    def _drain(self) -> None:
        try:
            while chunk := os.read(self._fd, 65536):
                self._tail += chunk
                del self._tail[:-STDERR_TAIL]
        finally:
            os.close(self._fd)

    def text(self, wait: float) -> str:
        """The tail, after waiting up to `wait` [s] for the child's stderr to close."""
        self._thread.join(wait)
        return bytes(self._tail).decode("utf-8", "replace").strip()


def _reap(process: subprocess.Popen[bytes]) -> None:
    """End `process` and wait for it: SIGTERM, then SIGKILL after `GRACE` [s]."""
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(GRACE)
        except subprocess.TimeoutExpired:
            process.kill()
    process.wait()
    for pipe in (process.stdin, process.stdout, process.stderr):
        if pipe is not None:
            pipe.close()


def _exit_status(code: int | None) -> str:
    if code is None:
        return "still running (killed)"
    if code < 0:
        return f"killed by signal {signal.Signals(-code).name}"
    return f"exit status {code}"


class RemoteStack:
    """A `DrivingStack` whose work is done by a child process (module doc).

    `name` and `version` are those the child gave in `ready`; `reads` the sensors it asked
    for (None: all). A camera's or LiDAR's frame crosses the pipe whole, so a stack reads
    only the sensors it uses."""

    def __init__(self, ctx: StackContext, command: Sequence[str], timeout: float = TIMEOUT,
                 start_timeout: float = START_TIMEOUT, cwd: Path | None = None,
                 env: Mapping[str, str] | None = None) -> None:
        if not command or len(command) > MAX_ARGS or not all(isinstance(a, str)
                                                             for a in command):
            raise ValueError(f"a remote stack's command: 1 to {MAX_ARGS} strings")
        self.ctx, self.command, self.timeout = ctx, tuple(command), timeout
        self._speed = 0.0  # [m/s] the odometry's last speed (`accel` commands by wire)
        self._closed = False
        self.process = subprocess.Popen(  # its own session: a terminal's ^C reaches avsim,
            self.command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,  # which reaps it
            stderr=subprocess.PIPE, cwd=cwd, env=None if env is None else dict(env),
            start_new_session=True)
        self._reaper = weakref.finalize(self, _reap, self.process)
        assert self.process.stdin and self.process.stdout and self.process.stderr
        self._stderr = _StderrTail(self.process.stderr.fileno())
        self._channel = Channel(self.process.stdin.fileno(), self.process.stdout.fileno(),
                                MAX_REPLY)
        try:
            self._send(wire.hello(ctx), start_timeout, "hello")
            self.name, self.version, self._reads = wire.ready(
                self._receive(start_timeout, "hello"))
        except BaseException:
            self.close()
            raise

    @property
    def reads(self) -> frozenset[str] | None:
        return self._reads

    def on_frames(self, t: float, frames: Frames) -> PerceptionReport | None:
        odometry = frames.get("odometry")
        if isinstance(odometry, Odometry):
            self._speed = odometry.speed
        with self.ctx.timer("remote"):
            self._send(wire.frames(t, frames, self._reads), self.timeout, "frames")
        return None

    def tick(self, t: float, dt: float) -> StackStep:
        with self.ctx.timer("remote"):
            self._send({"type": "tick", "t": t, "dt": dt}, self.timeout, "tick")
            message = self._receive(self.timeout, "tick")
        try:
            reply = wire.command(message)
            channels = wire.channels(message)
        except wire.WireError as exc:
            raise self._failed(f"answered garbage: {exc}") from None
        command: VehicleCommand = reply.torques if reply.torques is not None else \
            drive_by_wire(reply.steering_angle, reply.accel or 0.0, self._speed,
                          self.ctx.vehicle, reply.hazard_lights)
        return StackStep(command, channels=channels)

    def close(self) -> None:
        """Say `bye`, give the child `GRACE` [s] to exit, then end it; always reaps it."""
        if self._closed:
            return
        self._closed = True
        if self.process.poll() is None:
            with suppress(ChannelError, subprocess.TimeoutExpired):
                self._channel.send({"type": "bye"}, GRACE)
                self.process.wait(GRACE)
        self._reaper()

    def _send(self, message: Mapping[str, Any], timeout: float, what: str) -> None:
        try:
            self._channel.send(message, timeout)
        except ChannelError as exc:
            raise self._channel_failed(exc, what, timeout) from None

    def _receive(self, timeout: float, what: str) -> dict[str, Any]:
        try:
            return self._channel.receive(timeout)
        except ChannelError as exc:
            raise self._channel_failed(exc, what, timeout) from None

    def _channel_failed(self, exc: ChannelError, what: str, timeout: float) -> RemoteStackError:
        if exc.kind == "timeout":
            return self._failed(f"did not answer {what} within {timeout:g} s")
        if exc.kind == "closed":
            return self._failed(f"{exc} at {what}", dying=True)
        return self._failed(f"answered garbage at {what}: {exc}")

    def _failed(self, problem: str, dying: bool = False) -> RemoteStackError:
        """The error for `problem`, once the child is ended and reaped: its exit status and
        the tail of its stderr. `dying`: it closed its pipes, so it is given `GRACE` [s] to
        exit of itself before it is ended."""
        code = self.process.poll()
        if code is None and dying:
            with suppress(subprocess.TimeoutExpired):
                code = self.process.wait(GRACE)
        self._closed = True
        self._reaper()
        tail = self._stderr.text(GRACE)
        said = f"; its stderr ends:\n{tail}" if tail else "; its stderr is empty"
        return RemoteStackError(f"the stack process {self.command[0]} {problem} "
                                f"({_exit_status(code)}){said}")


def remote(ctx: StackContext, command: Sequence[str], timeout: float = TIMEOUT,
           start_timeout: float = START_TIMEOUT, cwd: Path | None = None,
           env: Mapping[str, str] | None = None) -> RemoteStack:
    """The stack that runs `command` (the program and its arguments) as a child process:
    `timeout` [s] bounds each reply, `start_timeout` [s] the `ready`; `cwd` and `env` are
    the child's (None: avsim's)."""
    return RemoteStack(ctx, command, timeout, start_timeout, cwd, env)
