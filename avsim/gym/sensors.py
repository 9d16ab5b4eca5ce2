"""The `sensors` observation: the newest frame of each of the car's sensors, as arrays of
fixed shape (a `gymnasium.spaces.Dict` keyed by sensor name).

- a camera `NAME`: `NAME` uint8 (height, width, 3), the RGB image;
- the LiDAR: `lidar_points` float32 (rays, 3) [m], the returns in the sensor frame, the
  first `lidar_count` rows real and the rest zero; `lidar_count` int32 (1,);
- GNSS: `gnss` float32 (5,): x, y [m] map frame, heading [rad], sigma [m], valid (1 or 0;
  in an outage or before the first fix the rest are 0);
- odometry: `odometry` float32 (6,): wheel spin rates FL, FR, RL, RR [rad/s], yaw rate
  [rad/s], measured road-wheel angle [rad] (0 before the first sample).

A frame stays until its sensor's next one arrives (each sensor at its own rate).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from world.frames import (
    CameraFrame,
    CameraInfo,
    Frame,
    GnssFix,
    LidarInfo,
    LidarScan,
    Odometry,
    SensorKind,
    SensorSpec,
)

Observation = dict[str, NDArray[np.generic]]
GNSS_SIZE = 5  # x, y, heading, sigma, valid
ODOMETRY_SIZE = 6  # four wheel spin rates, yaw rate, steering angle


def _unbounded(size: int) -> spaces.Box:
    return spaces.Box(-np.inf, np.inf, (size,), np.float32)


class SensorObservation:
    """The space and the arrays of the `sensors` observation for the car's `specs`."""

    def __init__(self, specs: Sequence[SensorSpec]) -> None:
        self.specs = tuple(specs)
        parts: dict[str, spaces.Space[object]] = {}
        for spec in self.specs:
            if spec.kind is SensorKind.CAMERA:
                assert isinstance(spec.info, CameraInfo)
                parts[spec.name] = spaces.Box(0, 255, (spec.info.height, spec.info.width, 3),
                                              np.uint8)
            elif spec.kind is SensorKind.LIDAR:
                assert isinstance(spec.info, LidarInfo)
                rays, reach = spec.info.rays, spec.info.max_range
                parts["lidar_points"] = spaces.Box(-reach, reach, (rays, 3), np.float32)
                parts["lidar_count"] = spaces.Box(0, rays, (1,), np.int32)
            elif spec.kind is SensorKind.GNSS:
                parts[spec.name] = _unbounded(GNSS_SIZE)
            else:
                parts[spec.name] = _unbounded(ODOMETRY_SIZE)
        self.space = spaces.Dict(parts)

    def encode(self, latest: Mapping[str, Frame]) -> Observation:
        """The observation of the newest frames by sensor name (zeros for a sensor that has
        given none yet)."""
        out: Observation = {k: np.zeros(s.shape or (), s.dtype)
                            for k, s in self.space.spaces.items()}
        for spec in self.specs:
            frame = latest.get(spec.name)
            if isinstance(frame, CameraFrame):
                out[spec.name] = np.ascontiguousarray(frame.rgb, dtype=np.uint8)
            elif isinstance(frame, LidarScan):
                self._lidar(frame, out)
            elif isinstance(frame, GnssFix):
                out[spec.name] = _gnss(frame)
            elif isinstance(frame, Odometry):
                out[spec.name] = np.array([*frame.wheel_speeds, frame.yaw_rate,
                                           frame.steering_angle], np.float32)
        return out

    def _lidar(self, scan: LidarScan, out: Observation) -> None:
        """The scan's returns, padded (at most the revolution's rays), into `out`."""
        points = out["lidar_points"]
        n = min(len(scan.points), len(points))
        reach = scan.info.max_range
        points[:n] = np.clip(scan.points[:n], -reach, reach)
        out["lidar_count"] = np.array([n], np.int32)


def _gnss(fix: GnssFix) -> NDArray[np.float32]:
    """[x, y, heading, sigma, valid] of a fix; an outage's is all zero."""
    if not fix.valid:
        return np.zeros(GNSS_SIZE, np.float32)
    return np.array([fix.x, fix.y, fix.heading, fix.sigma, 1.0], np.float32)
