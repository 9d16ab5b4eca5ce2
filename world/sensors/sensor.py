"""The one interface of the car's sensors: a name, a rate, a latency and a capture.

A `Sensor` captures at its rate (`world.core.rates`: every step that is a multiple of its
period), from the ego's TRUE state (the sensor is on the real body), and hands over one
`Frame` (`world.frames`) that reaches the stack `latency` seconds later. What else it knows
about the capture (what each LiDAR return really hit) rides beside the frame as ground
truth, for scoring and the recording, never for the stack.

Where a sensor captures (this process, or a worker rendering a mirror of the world) is the
pipeline's business (`world.sensors.pipeline`); when, the schedule's
(`world.sensors.schedule`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from world.core.rates import Rate
from world.ego.body import EgoTruth
from world.frames import Frame


@dataclass(frozen=True, slots=True, eq=False)
class Reading:
    """One sensor's capture: the frame for the stack and the ground truth beside it."""

    sensor: str  # the sensor's name
    frame: Frame  # what the stack gets
    truth: object | None = None  # ground truth of the capture, never for the stack (a
    #   LiDAR scan's: `world.sensors.lidar.LidarTruth`)


@runtime_checkable
class Sensor(Protocol):
    """A sensor on the car."""

    @property
    def name(self) -> str:
        """Unique on the car ("front", "lidar", "gnss", ...): the key of its entry in the
        rates table and of its frames in a capture."""

    @property
    def rate(self) -> Rate:
        """Its capture rate (it captures at the steps where this rate fires)."""

    @property
    def latency(self) -> float:
        """[s] from a capture to its delivery to the stack (a whole number of steps)."""

    def capture(self, t: float, ego: EgoTruth) -> Reading:
        """The reading at time `t` [s] with the ego in its true state `ego`."""


def vehicle_pose(truth: EgoTruth, ride_height: float) -> tuple[NDArray[np.float64],
                                                             NDArray[np.float64]]:
    """The vehicle frame's world pose: origin (3,) [m] on the ground below the car's centre
    (in the body's own down direction) and rotation (3, 3) vehicle -> world."""
    origin = truth.position - truth.rotation[:, 2] * ride_height
    return origin, truth.rotation
