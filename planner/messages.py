"""What the planner hands to control. A leaf module: dataclasses only.

`Plan.ego` carries the state estimate the plan was made from, so that control needs no
other input: arrows run one way, world frames -> perception -> planner -> control.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from perception.messages import EgoState

__all__ = ["EgoState", "Plan", "ReferencePath"]


@dataclass(frozen=True, slots=True, eq=False)
class ReferencePath:
    """A path for the lateral controller, sampled ahead of (and a little behind) the car."""

    xy: NDArray[np.float64]  # [m] (N, 2) map frame points, N >= 2, spaced about `spacing`
    heading: NDArray[np.float64]  # [rad] (N,) path tangent, counter-clockwise from +x
    curvature: NDArray[np.float64]  # [1/m] (N,) signed, > 0 turns left


@dataclass(frozen=True, slots=True, eq=False)
class Plan:
    t: float  # [s] sim time the plan was made at
    ego: EgoState  # the estimate the plan was made from
    path: ReferencePath  # the path to follow (map frame)
    target_speed: float  # [m/s] speed to hold now
    target_accel: float  # [m/s^2] feed-forward acceleration, signed (< 0 braking ahead of a limit)
    speed_limit: float  # [m/s] posted limit in force at the front bumper
    station: float  # [m] the ego's station on the route (from the map and its own estimate)
    lateral_error: float  # [m] the planner's view of the ego's offset from the path, left +
