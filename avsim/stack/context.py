"""What a stack is built with (`StackContext`): the car, its sensors, the static map and
what its driver asks. A stack's factory gets one and returns the stack or the stage."""

from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass, field

from world.frames import SensorSpec, VehicleInfo
from world.hdmap import RoadMap

API_VERSION = "1.1"  # the stack API's version: the major number changes when a stack written
#   for an earlier one may no longer run unchanged, the minor when something is added

Timer = Callable[[str], AbstractContextManager[object]]  # a stage's name -> a span timing it


def untimed(stage: str) -> AbstractContextManager[object]:
    """A `Timer` that times nothing."""
    return nullcontext()


@dataclass(frozen=True, slots=True, eq=False)
class StackContext:
    """Everything a stack may know before the run starts (SI units; map frame as
    `world.frames` says)."""

    road: RoadMap  # the static HD map: lanes, limits, signs, stop lines, light heads
    vehicle: VehicleInfo  # the car's dimensions, mass, wheels and steering limit
    sensors: tuple[SensorSpec, ...]  # every sensor on the car: name, kind, rate, latency,
    #   calibration (a delivery's frames are keyed by these names)
    start_lane: int  # [-] the lane the car starts in (ego-direction index, 0 rightmost)
    set_speed: float  # [m/s] the speed the driver set (the cruise set speed)
    max_speed: float  # [m/s] the car's own speed limit
    overtake: bool  # the driver allows lane changes to pass a slower vehicle
    seed: int  # the run's seed (a stack that draws random numbers draws them from it)
    timer: Timer = field(default=untimed)  # times a stage's parts by name (the run's
    #   report of where its wall time goes); a stack may ignore it
