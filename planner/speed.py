"""A speed reference, and the plan's record of which constraint set it.

The planner's speed is a chain (`planner.planner`): the map's plan (set speed, limits,
curves; `planner.speed_planning`), the driver's pedal (`planner.driver_override`), the ACC /
event law (`planner.acc_layer`), the degraded lane's cap and the emergency stop. Each link
takes a `PlannedSpeed` and returns one: its own reference and `SpeedSource` where it lowers
(or, for the pedal, sets) the speed, the one it was given otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass

from planner.messages import SpeedSource
from planner.speed_planning import Binding


@dataclass(frozen=True, slots=True)
class SpeedRef:
    speed: float  # [m/s] target speed
    accel: float  # [m/s^2] feed-forward, signed


@dataclass(frozen=True, slots=True)
class PlannedSpeed:
    """A speed reference and the constraint that set it."""

    ref: SpeedRef
    source: SpeedSource


BINDING_SOURCE = {  # the map plan's binding constraint, as a source of the plan's speed
    Binding.SET_SPEED: SpeedSource.SET_SPEED,
    Binding.MAX_SPEED: SpeedSource.SET_SPEED,  # the set speed, capped at the vehicle's
    Binding.SIGHT: SpeedSource.SIGHT,  # capped at what the forward sensing range covers
    Binding.LIMIT: SpeedSource.LIMIT,
    Binding.LIMIT_AHEAD: SpeedSource.LIMIT,
    Binding.CURVE: SpeedSource.CURVE,
    Binding.CURVE_AHEAD: SpeedSource.CURVE,
    Binding.CROSSING: SpeedSource.LIMIT,  # a crossing's speed, like a posted limit
}
