"""Sensor faults applied to the data the stack receives (the scenario's fault events).

`FaultySensing` wraps a sensing pipeline (`world.sensors.pipeline`: inline or process, which
give bitwise the same data): at each submission it notes the faults running at the capture's
instant (`world.World.sensor_faults`), and at collection it hands every capture through a
`FaultInjector`, in submission order, whatever the pipeline. So both pipelines give bitwise
the same faulty data too. What each fault does to its sensor's readings:

- `camera_blackout`: every pixel of the camera's image is 0 (black);
- `camera_freeze`: the camera's image is the one it delivered last before the fault (its
  timestamp keeps running: a hung image pipeline re-sending its buffer);
- `lidar_outage`: no scan arrives (the reading is dropped from its capture);
- `gnss_outage`: every fix is flagged invalid (NaN position and heading), as the receiver's
  own dropouts are (`world.sensors.gnss`);
- `gnss_jump`: every fix is moved by the fault's (x, y) offset, its stated accuracy unchanged.

The frames carry no flag: the stack must notice a fault from the data alone
(`perception.health`). The ground truth beside a reading (`Reading.truth`) is kept as it was.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from world.core.rendering import Renderer
from world.frames import CameraFrame, GnssFix, LidarScan
from world.sensors.pipeline import Capture, Sensing
from world.sensors.schedule import Due
from world.sensors.sensor import Reading
from world.spec import (
    CameraBlackout,
    CameraFreeze,
    GnssJump,
    GnssOutage,
    LidarOutage,
    SensorFault,
)


class FaultInjector:
    """Applies the running faults to one capture's readings at a time, in capture order (it
    remembers each camera's last delivered image, for a freeze)."""

    def __init__(self) -> None:
        self._last: dict[str, NDArray[np.uint8]] = {}  # per camera: the image delivered last
        self._frozen: dict[str, NDArray[np.uint8]] = {}  # per frozen camera: its held image

    def apply(self, readings: tuple[Reading, ...],
              faults: tuple[SensorFault, ...]) -> tuple[Reading, ...]:
        """`readings` of one capture as the faults `faults` (running at its instant) make
        them; a dropped reading is left out."""
        frozen = {f.camera for f in faults if isinstance(f, CameraFreeze)}
        self._frozen = {name: rgb for name, rgb in self._frozen.items() if name in frozen}
        out = []
        for reading in readings:
            faulty = self._reading(reading, faults)
            if faulty is not None:
                out.append(faulty)
        return tuple(out)

    def _reading(self, reading: Reading, faults: tuple[SensorFault, ...]) -> Reading | None:
        frame = reading.frame
        if isinstance(frame, CameraFrame):
            return replace(reading, frame=self._camera(frame, faults))
        if isinstance(frame, LidarScan):
            return None if any(isinstance(f, LidarOutage) for f in faults) else reading
        if isinstance(frame, GnssFix):
            return replace(reading, frame=_gnss(frame, faults))
        return reading

    def _camera(self, frame: CameraFrame, faults: tuple[SensorFault, ...]) -> CameraFrame:
        name = frame.info.name
        rgb = frame.rgb
        if any(isinstance(f, CameraFreeze) and f.camera == name for f in faults):
            rgb = self._frozen.setdefault(name, self._last.get(name, rgb))
        if any(isinstance(f, CameraBlackout) and f.camera == name for f in faults):
            rgb = np.zeros_like(rgb)
        self._last[name] = rgb
        return frame if rgb is frame.rgb else replace(frame, rgb=rgb)


def _gnss(fix: GnssFix, faults: tuple[SensorFault, ...]) -> GnssFix:
    if any(isinstance(f, GnssOutage) for f in faults):
        return replace(fix, x=math.nan, y=math.nan, heading=math.nan, valid=False)
    for fault in faults:
        if isinstance(fault, GnssJump) and fix.valid:
            fix = replace(fix, x=fix.x + fault.offset[0], y=fix.y + fault.offset[1])
    return fix


class FaultySensing:
    """A sensing pipeline whose captures carry the faults running at their instant."""

    def __init__(self, inner: Sensing, faults: Callable[[], tuple[SensorFault, ...]]) -> None:
        """`inner`: the pipeline; `faults`: the faults running now (asked at each
        submission, the capture's instant)."""
        self._inner = inner
        self._faults = faults
        self._injector = FaultInjector()
        self._running: dict[Due, tuple[SensorFault, ...]] = {}  # per submitted capture
        self.renderer: Renderer | None = inner.renderer

    def submit(self, due: Due) -> None:
        self._running[due] = self._faults()
        self._inner.submit(due)

    def collect(self, step: int) -> tuple[Capture, ...]:
        captures = self._inner.collect(step)
        return tuple(Capture(c.due, self._injector.apply(c.readings, self._running.pop(c.due)))
                     for c in captures)

    def close(self) -> None:
        self._inner.close()
        self._running.clear()
