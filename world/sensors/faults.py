"""Sensor faults applied to the data the stack receives (the scenario's fault events).

`FaultySensing` wraps a sensing pipeline (`world.sensors.pipeline`: inline or process, which
give bitwise the same data): at each submission it notes the faults running at the capture's
instant (`world.World.sensor_faults`), and at collection it hands every capture through a
`FaultInjector`, in submission order, whatever the pipeline. So both pipelines give bitwise
the same faulty data too. What each fault does to its sensor's readings:

- `camera_blackout`: every pixel of the camera's image is 0 (black);
- `camera_freeze`: the camera's image is the one it delivered last before the fault (its
  timestamp keeps running: a hung image pipeline re-sending its buffer);
- `camera_occlusion`: a strip of `fraction` of the image's width, from its left or right
  edge, is black (an opaque dark cover: mud, a leaf);
- `sensor_delay`: each capture of the sensor is replaced by its own capture from `delay`
  seconds earlier (its stamp that old: the data arrive `delay` later than its latency), or
  left out when there is none that old; the other faults then apply to it;
- `lidar_outage`: no scan arrives (the reading is dropped from its capture);
- `gnss_outage`: every fix is flagged invalid (NaN position and heading), as the receiver's
  own dropouts are (`world.sensors.gnss`);
- `gnss_jump`: every fix is moved by the fault's (x, y) offset, its stated accuracy unchanged.

The frames carry no flag: the stack must notice a fault from the data alone
(`perception.health`). The ground truth beside a reading (`Reading.truth`) is kept as it was.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Iterable, Mapping
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from world.core.rendering import Renderer
from world.frames import CameraFrame, GnssFix, LidarScan
from world.hdmap import Side
from world.sensors.pipeline import Capture, Sensing
from world.sensors.schedule import Due
from world.sensors.sensor import Reading
from world.spec import (
    CameraBlackout,
    CameraFreeze,
    CameraOcclusion,
    GnssJump,
    GnssOutage,
    LidarOutage,
    SensorDelay,
    SensorFault,
)

STAMP_TOLERANCE = 1e-9  # [s] a capture `delay` earlier is found despite float sums


class FaultInjector:
    """Applies the running faults to one capture's readings at a time, in capture order (it
    remembers each camera's last delivered image, for a freeze)."""

    def __init__(self, delays: Mapping[str, float] | None = None) -> None:
        """`delays`: per sensor that a `sensor_delay` may hit, the longest delay [s] (its
        captures that old are kept)."""
        self._last: dict[str, NDArray[np.uint8]] = {}  # per camera: the image delivered last
        self._frozen: dict[str, NDArray[np.uint8]] = {}  # per frozen camera: its held image
        self._keep = dict(delays or {})
        self._history: dict[str, deque[Reading]] = {name: deque() for name in self._keep}

    def apply(self, readings: tuple[Reading, ...],
              faults: tuple[SensorFault, ...]) -> tuple[Reading, ...]:
        """`readings` of one capture as the faults `faults` (running at its instant) make
        them; a dropped reading is left out."""
        frozen = {f.camera for f in faults if isinstance(f, CameraFreeze)}
        self._frozen = {name: rgb for name, rgb in self._frozen.items() if name in frozen}
        out = []
        for reading in readings:
            delayed = self._delayed(reading, faults)
            faulty = None if delayed is None else self._reading(delayed, faults)
            if faulty is not None:
                out.append(faulty)
        return tuple(out)

    def _delayed(self, reading: Reading, faults: tuple[SensorFault, ...]) -> Reading | None:
        """The sensor's capture from its delay earlier (`reading` itself without a delay;
        None when there is none that old), remembering `reading`."""
        history = self._history.get(reading.sensor)
        if history is None:
            return reading
        t = reading.frame.t
        history.append(reading)
        while history[0].frame.t < t - self._keep[reading.sensor] - 0.5:
            history.popleft()  # 0.5 s more than the longest delay: one that old is there
        delay = max((f.delay for f in faults
                     if isinstance(f, SensorDelay) and f.sensor == reading.sensor), default=0.0)
        if delay == 0.0:
            return reading
        return next((r for r in reversed(history)
                     if r.frame.t <= t - delay + STAMP_TOLERANCE), None)

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
        for fault in faults:
            if isinstance(fault, CameraOcclusion) and fault.camera == name:
                rgb = _occluded(rgb, fault)
        if any(isinstance(f, CameraBlackout) and f.camera == name for f in faults):
            rgb = np.zeros_like(rgb)
        self._last[name] = rgb
        return frame if rgb is frame.rgb else replace(frame, rgb=rgb)


def _occluded(rgb: NDArray[np.uint8], fault: CameraOcclusion) -> NDArray[np.uint8]:
    """`rgb` (H, W, 3) with the fault's strip black: `fraction` of the columns, from the left
    (u = 0, the car's left) or the right edge."""
    out = rgb.copy()
    width = rgb.shape[1]
    n = min(width, round(fault.fraction * width))
    if fault.side is Side.LEFT:
        out[:, :n] = 0
    else:
        out[:, width - n:] = 0
    return out


def _gnss(fix: GnssFix, faults: tuple[SensorFault, ...]) -> GnssFix:
    if any(isinstance(f, GnssOutage) for f in faults):
        return replace(fix, x=math.nan, y=math.nan, heading=math.nan, valid=False)
    for fault in faults:
        if isinstance(fault, GnssJump) and fix.valid:
            fix = replace(fix, x=fix.x + fault.offset[0], y=fix.y + fault.offset[1])
    return fix


class FaultySensing:
    """A sensing pipeline whose captures carry the faults running at their instant."""

    def __init__(self, inner: Sensing, faults: Callable[[], tuple[SensorFault, ...]],
                 delays: Mapping[str, float] | None = None) -> None:
        """`inner`: the pipeline; `faults`: the faults running now (asked at each
        submission, the capture's instant); `delays`: the longest `sensor_delay` per sensor
        (`sensor_delays`)."""
        self._inner = inner
        self._faults = faults
        self._injector = FaultInjector(delays)
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


def sensor_delays(faults: Iterable[object]) -> dict[str, float]:
    """[s] per sensor, the longest `sensor_delay` among `faults` (a scenario's events')."""
    delays: dict[str, float] = {}
    for fault in faults:
        if isinstance(fault, SensorDelay):
            delays[fault.sensor] = max(delays.get(fault.sensor, 0.0), fault.delay)
    return delays
