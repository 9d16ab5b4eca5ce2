"""Sensing pipelines: where the sensor rig captures, and when the stack gets each capture.

The sensor loop submits each `Due` of the schedule (`world.sensors.schedule`) at its step; a
pipeline captures its sensors on the ego's true pose at that step and hands the `Capture`
back when its delivery step has come: at once for GNSS and odometry, one 10 Hz period later
for camera frames and LiDAR scans (`world.core.rates.FRAME_LATENCY`, the time a real camera /
LiDAR pipeline needs to expose, read out and hand over a frame; the stack compensates with
its own motion estimate). Two interchangeable pipelines give bitwise the same data:

- `InlineSensing`: every sensor in the simulated world's own rig, captured at submission;
- `ProcessSensing`: the sensors the simulated world's rig does not hold (the cameras: it is
  built without them) in a worker process holding a MIRROR of the world (built from the
  same scenario, posed from a `WorldSnapshot` at each capture), the rest (LiDAR: ray casting
  is a physics query; GNSS, odometry) in the simulated world's own rig. Rendering runs on the
  second core while the main process casts the LiDAR, steps physics and runs the stack; the
  main process waits for the frames only when they are due. The images come back through
  shared memory (`world.sensors.frame_slots`), the rest of each answer through the pipe.
  The worker (`SensingWorker`) can be started before the simulated world is built, so that
  the two worlds are built side by side (the runner does).

Given a `Stopwatch`, a pipeline times each capture in its process ("sensor <name>") and, for
the worker, the passing of data: "ipc send" (the snapshot and request out), "ipc wait"
(blocked on the worker), "ipc receive" (the frames in) and the worker's own stages
("worker pose", "worker sensor <name>", "worker ipc send").
"""

from __future__ import annotations

import multiprocessing as mp
import os
import tempfile
import time
import traceback
from collections import deque
from dataclasses import dataclass
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any, Protocol

from world.core.rendering import Renderer
from world.core.stopwatch import Stopwatch
from world.frames import Frame
from world.sensors import worker as sensing_worker
from world.sensors.forkserver import SensingProcess
from world.sensors.frame_slots import SLOTS, FrameSlots, shared_dir
from world.sensors.lidar import LidarSensor
from world.sensors.schedule import Due
from world.sensors.sensor import Reading
from world.sensors.setup import SensorSetup
from world.spec import WorldSpec
from world.world import World


class SensingError(RuntimeError):
    """The sensing worker failed (its traceback is in the message)."""


@dataclass(frozen=True, slots=True, eq=False)
class Capture:
    """What the sensors of one `Due` produced: it reaches the stack as one delivery."""

    due: Due  # which sensors, when captured, when delivered
    readings: tuple[Reading, ...]  # in the `Due`'s order

    @property
    def step(self) -> int:
        """[steps] physics step of the capture."""
        return self.due.step

    @property
    def t(self) -> float:
        """[s] sim time of the capture."""
        return self.due.t

    @property
    def frames(self) -> tuple[Frame, ...]:
        return tuple(r.frame for r in self.readings)


class Sensing(Protocol):
    renderer: Renderer | None  # the cameras' renderer (None: no cameras)

    def submit(self, due: Due) -> None:
        """Capture the sensors of `due` now (the simulated world is at step `due.step`)."""

    def collect(self, step: int) -> tuple[Capture, ...]:
        """The captures whose delivery step has come by physics step `step`, in the order
        they were submitted, and forget them."""

    def close(self) -> None: ...


def _check_now(world: World, due: Due) -> None:
    if due.step != world.clock.step:
        raise ValueError(f"a capture due at step {due.step} submitted at {world.clock.step}")


class InlineSensing:
    """Captures every sensor in the simulated world's own rig."""

    def __init__(self, world: World, watch: Stopwatch | None = None) -> None:
        self._world = world
        self._watch = watch
        self.renderer: Renderer | None = world.renderer
        self._pending: list[tuple[int, Capture]] = []  # (delivery step, capture)

    def submit(self, due: Due) -> None:
        w = self._world
        _check_now(w, due)
        readings = w.rig.capture(due.sensors, due.t, w.ego_truth, self._watch)
        self._pending.append((due.deliver, Capture(due, readings)))

    def collect(self, step: int) -> tuple[Capture, ...]:
        ready = tuple(capture for deliver, capture in self._pending if deliver <= step)
        self._pending = [(d, c) for d, c in self._pending if d > step]
        return ready

    def close(self) -> None:
        self._pending = []


@dataclass(slots=True, eq=False)
class _Pending:
    """A submitted `Due`: its local readings, and the worker's once received."""

    due: Due
    remote: tuple[str, ...]  # the sensors the worker captures
    local: tuple[Reading, ...] = ()
    received: tuple[Reading, ...] | None = None


LIGHT_RENDERING = 10e6  # [px/s] below this the worker renders on one llvmpipe thread


def render_threads(setup: SensorSetup) -> int:
    """llvmpipe threads for the worker (0: Mesa's choice, every core). Where its cameras are
    light (`fast`, `default`: 3-4 Mpx/s) the main process is the bottleneck, and a second
    render thread only takes its core: one thread made `default` 6 % faster (three
    interleaved pairs). Where they are heavy (`paper`: 37 Mpx/s) the worker is the
    bottleneck, and two threads were 2-3 % faster (five pairs of six)."""
    pixels = sum(c.width * c.height * setup.timing(c.name).rate.hz for c in setup.cameras)
    return 1 if pixels < LIGHT_RENDERING else 0


class SensingWorker:
    """The worker process of a `ProcessSensing`, started on its own: it builds its mirror of
    the scenario's world while the main process builds the simulated one (about 2 s and 1 s
    here, side by side instead of one after the other).

    Workers are forked from a forkserver of their own (`world.sensors.forkserver`): a fresh
    interpreter (no physics or GL state is ever inherited) that has imported its preload
    once, so that the second and later workers of a process (a test session's runs) start
    without the imports and the EGL plugin's symbol scan (about 2 s a run,
    `world.sensors.warm`); the first costs what a spawned worker did. The server is the
    same whatever else the starting process has done (a batch's forkserver has another
    preload), so a worker starts the same everywhere. The worker gets this process's
    environment and directory at its start, as a spawned one would (the forkserver's are
    those of its own start)."""

    def __init__(self, spec: WorldSpec, setup: SensorSetup) -> None:
        self.spec = spec
        fd, name = tempfile.mkstemp(prefix="avsim-frames-", dir=shared_dir())
        os.close(fd)
        self.slots = FrameSlots(Path(name), setup.cameras, create=True)
        self._conn, child = mp.Pipe()
        self._proc = SensingProcess(target=sensing_worker.main,
                                    args=(child, spec, setup, self.slots.path,
                                          render_threads(setup), dict(os.environ),
                                          os.getcwd()),
                                    name="avsim-sensing", daemon=True)
        self._proc.start()
        child.close()
        self._renderer: Renderer | None = None

    @property
    def renderer(self) -> Renderer:
        """The worker's renderer, once its world is built (waits for it the first time)."""
        if self._renderer is None:
            try:
                self._renderer = Renderer(self.receive())
            finally:  # both processes have it mapped now (or the worker failed): nothing
                self.slots.path.unlink(missing_ok=True)  # is left in shared memory
        return self._renderer

    def send(self, message: tuple[Any, ...]) -> None:
        self._conn.send(message)

    def poll(self) -> None:
        """Block until the worker has answered."""
        self._conn.poll(None)

    def receive(self) -> Any:
        try:
            kind, payload = self._conn.recv()
        except EOFError as e:
            self._proc.join(timeout=5)  # reap it, for its exit code (-N: killed by signal N)
            raise SensingError(f"sensing worker exited (code {self._proc.exitcode})") from e
        if kind == "error":
            raise SensingError(f"sensing worker failed:\n{payload}")
        return payload

    def close(self, unanswered: int = 0) -> None:
        """Take the `unanswered` answers still due off the pipe, stop the worker, drop the
        slots."""
        if self._proc.is_alive():
            if self._renderer is None:  # never asked for anything (still building its
                self._proc.kill()  # world, perhaps): nothing of it to wait for
            else:
                try:
                    for _ in range(unanswered):
                        self.receive()
                    self._conn.send(("close",))
                except (OSError, EOFError, SensingError):
                    pass
            self._proc.join(timeout=10)
            if self._proc.is_alive():
                self._proc.kill()
        self._conn.close()
        self.slots.close()
        self.slots.path.unlink(missing_ok=True)


class ProcessSensing:
    """The sensors `world`'s rig lacks (its cameras: `world` must be built without them,
    `World(spec, setup, cameras=False)`) in a worker process on a mirror of `world`, the
    others in `world`."""

    def __init__(self, world: World, setup: SensorSetup, watch: Stopwatch | None = None,
                 worker: SensingWorker | None = None) -> None:
        """`worker`: one started earlier for `world`'s scenario (else one starts now)."""
        if world.renderer is not None:
            raise ValueError("ProcessSensing needs a World built without cameras")
        if worker is not None and worker.spec is not world.spec:
            raise ValueError("the sensing worker was started for another world")
        self._world = world
        self._watch = watch
        for sensor in world.rig:
            if isinstance(sensor, LidarSensor):
                sensor.lidar.threads = 1  # the other core renders: no oversubscription
        self._worker = worker if worker is not None else SensingWorker(world.spec, setup)
        self.renderer: Renderer | None = self._worker.renderer
        self._pending: list[_Pending] = []  # in submission order
        self._awaiting: deque[_Pending] = deque()  # sent to the worker, unanswered, in order
        self._answered = 0  # answers received from the worker

    def submit(self, due: Due) -> None:
        w = self._world
        _check_now(w, due)
        pending = _Pending(due, tuple(n for n in due.sensors if n not in w.rig))
        if pending.remote:  # first, so that the worker renders while this process casts
            while len(self._awaiting) >= SLOTS:  # free the image slot this request takes
                self._answer_oldest()
            start = time.perf_counter()
            self._worker.send(("capture", due.t, w.snapshot(), pending.remote))
            self._time("ipc send", start)
            self._awaiting.append(pending)
        pending.local = w.rig.capture([n for n in due.sensors if n in w.rig], due.t,
                                      w.ego_truth, self._watch)
        self._pending.append(pending)

    def collect(self, step: int) -> tuple[Capture, ...]:
        ready = [p for p in self._pending if p.due.deliver <= step]
        self._pending = [p for p in self._pending if p.due.deliver > step]
        return tuple(self._assemble(p) for p in ready)

    def _assemble(self, pending: _Pending) -> Capture:
        """The capture of `pending`, its worker's readings received (the worker answers in
        the order it was asked)."""
        while pending.remote and pending.received is None:
            self._answer_oldest()
        by_name = {r.sensor: r for r in (*pending.local, *(pending.received or ()))}
        due = pending.due
        return Capture(due, tuple(by_name[name] for name in due.sensors))

    def _answer_oldest(self) -> None:
        """Receive the worker's answer to the oldest unanswered request, its images copied
        out of their slots."""
        start = time.perf_counter()
        self._worker.poll()
        self._time("ipc wait", start)
        start = time.perf_counter()
        readings, seconds = self._worker.receive()
        request, self._answered = self._answered, self._answered + 1
        slots = self._worker.slots
        self._awaiting.popleft().received = tuple(
            slots.take(request, r) if r.sensor in slots else r for r in readings)
        self._time("ipc receive", start)
        if self._watch is not None:
            self._watch.add_all(seconds, prefix="worker ")

    def close(self) -> None:
        self._worker.close(unanswered=len(self._awaiting))
        self._awaiting.clear()

    def _time(self, stage: str, start: float) -> None:
        if self._watch is not None:
            self._watch.add(stage, time.perf_counter() - start)


def serve(conn: Connection, spec: WorldSpec, setup: SensorSetup, slots_file: Path) -> None:
    """The worker: build the mirror world (cameras, no LiDAR), then capture on request until
    told to close; the images go into `slots_file`'s slots (`FrameSlots`)."""
    try:
        world = World(spec, setup, lidar=False)
        assert world.renderer is not None
        slots = FrameSlots(slots_file, setup.cameras, create=False)
        conn.send(("ready", world.renderer.value))
        sent = 0.0  # [s]
        request = 0
        while True:
            message = conn.recv()
            if message[0] == "close":
                break
            _, t, snapshot, names = message
            watch = Stopwatch()
            if sent:  # the previous answer's send (this one's is in the next answer)
                watch.add("ipc send", sent)
            with watch("pose"):
                world.apply_snapshot(snapshot)
            readings = world.rig.capture(names, t, world.ego_truth, watch)
            start = time.perf_counter()
            readings = tuple(slots.put(request, r) if r.sensor in slots else r
                             for r in readings)
            conn.send(("data", (readings, watch.seconds)))
            sent = time.perf_counter() - start
            request += 1
        slots.close()
        world.close()
    except Exception:  # report any failure to the main process, which raises it
        conn.send(("error", traceback.format_exc()))
    finally:
        conn.close()
