"""Sensing pipelines: when and where the sensor rig captures, and when the stack gets it.

A capture is taken at the sensors' instants on the ego's true pose and delivered to the
stack ONE SENSOR PERIOD LATER (100 ms at 10 Hz): the time a real camera / LiDAR pipeline
needs to expose, read out and hand over a frame. The stack compensates with its own motion
estimate. Two interchangeable pipelines give bitwise the same data:

- `InlineSensing`: the rig in the simulated world's own client, captured at submission;
- `ProcessSensing`: the cameras in a worker process holding a MIRROR of the world (built from
  the same scenario, posed from a `WorldSnapshot` at each capture), the LiDAR in the
  simulated world's own client (ray casting is a physics query). Rendering runs on the
  second core while the main process casts the LiDAR, steps physics and runs the stack; the
  main process waits for the frames only when they are due, one period later.
"""

from __future__ import annotations

import multiprocessing as mp
import traceback
from multiprocessing.connection import Connection
from typing import Protocol

from world.core.rendering import Renderer
from world.sensors import worker as sensing_worker
from world.sensors.rig import Due, SensorData
from world.sensors.setup import SensorSetup
from world.spec import WorldSpec
from world.world import World


class SensingError(RuntimeError):
    """The sensing worker failed (its traceback is in the message)."""


class Sensing(Protocol):
    renderer: Renderer

    def submit(self, t: float, due: Due) -> None:
        """Capture what is `due` now (the simulated world's current state)."""

    def collect(self) -> SensorData | None:
        """The capture submitted last (None if there is none), and forget it."""

    def close(self) -> None: ...


class InlineSensing:
    """Captures in the simulated world itself (its rig must have cameras and LiDAR)."""

    def __init__(self, world: World) -> None:
        if world.rig is None or world.renderer is None or not world.rig.has_lidar:
            raise ValueError("InlineSensing needs a World built with cameras and LiDAR")
        self._world = world
        self._rig = world.rig
        self.renderer = world.renderer
        self._pending: SensorData | None = None

    def submit(self, t: float, due: Due) -> None:
        w = self._world
        self._pending = self._rig.capture(t, w.ego_truth, due.cameras, due.lidar)

    def collect(self) -> SensorData | None:
        data, self._pending = self._pending, None
        return data

    def close(self) -> None:
        self._pending = None


class ProcessSensing:
    """Cameras in a worker process on a mirror of `world`, LiDAR in `world` (which must have
    been built with a LiDAR-only rig: `World(spec, setup, cameras=False)`)."""

    def __init__(self, world: World, setup: SensorSetup) -> None:
        if world.rig is None or world.rig.has_cameras or not world.rig.has_lidar:
            raise ValueError("ProcessSensing needs a World with a LiDAR-only rig")
        self._world = world
        self._rig = world.rig
        self._rig.lidar_threads = 1  # the other core renders: no oversubscription
        ctx = mp.get_context("spawn")  # a fresh interpreter: no inherited physics or GL state
        self._conn, child = ctx.Pipe()
        self._proc = ctx.Process(target=sensing_worker.main, args=(child, world.spec, setup),
                                 name="avsim-sensing", daemon=True)
        self._proc.start()
        child.close()
        self.renderer = Renderer(self._receive())
        self._pending: SensorData | None = None  # the LiDAR part, waiting for the frames

    def submit(self, t: float, due: Due) -> None:
        if self._pending is not None:
            raise RuntimeError("collect the last capture before submitting the next")
        self._conn.send(("capture", t, self._world.snapshot(), due.cameras))
        self._pending = self._rig.capture(t, self._world.ego_truth, (), due.lidar)

    def collect(self) -> SensorData | None:
        lidar, self._pending = self._pending, None
        if lidar is None:
            return None
        frames = self._receive()
        assert isinstance(frames, SensorData)
        return SensorData(lidar.t, frames.frames, lidar.scan, lidar.scan_truth)

    def close(self) -> None:
        if self._proc.is_alive():
            try:
                if self._pending is not None:
                    self._receive()
                self._conn.send(("close",))
            except (OSError, EOFError, SensingError):
                pass
            self._proc.join(timeout=10)
            if self._proc.is_alive():
                self._proc.kill()
        self._conn.close()

    def _receive(self) -> object:
        try:
            kind, payload = self._conn.recv()
        except EOFError as e:
            raise SensingError(f"sensing worker exited (code {self._proc.exitcode})") from e
        if kind == "error":
            raise SensingError(f"sensing worker failed:\n{payload}")
        return payload


def serve(conn: Connection, spec: WorldSpec, setup: SensorSetup) -> None:
    """The worker: build the mirror world, then render on request until told to close."""
    try:
        world = World(spec, setup, lidar=False)
        assert world.rig is not None and world.renderer is not None
        conn.send(("ready", world.renderer.value))
        while True:
            message = conn.recv()
            if message[0] == "close":
                break
            _, t, snapshot, cameras = message
            world.apply_snapshot(snapshot)
            conn.send(("data", world.rig.capture(t, world.ego_truth, cameras, False)))
        world.close()
    except Exception:  # report any failure to the main process, which raises it
        conn.send(("error", traceback.format_exc()))
    finally:
        conn.close()
