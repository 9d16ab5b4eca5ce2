"""The environment's reward (docs/stack-api.md, "Gymnasium"): dense, in metres of progress.

Per step of duration dt [s]:

    r = ds - LANE_WEIGHT * |e_lane| * dt - JERK_WEIGHT * |a_k - a_(k-1)|

- ds [m]: the car's true progress along its route over the step (the station `completes`
  measures);
- e_lane [m]: the car's true centre offset from the centre of the lane it is in, at the
  step's end (the margin `tyres_in_lane` judges the tyres by), at most `MAX_LANE_ERROR`;
- a_k - a_(k-1) [m/s^2]: the change of the asked acceleration from the last step (the
  comfort criteria's jerk, at the agent's own rate);

and once, at the step that ends the episode for a failed criterion, a contact or an error,
`-FAIL_PENALTY`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

LANE_WEIGHT = 1.0  # [1/s] metres of progress lost per metre of lane offset, per second
JERK_WEIGHT = 0.05  # [s^2] metres lost per m/s^2 of change in the asked acceleration
MAX_LANE_ERROR = 5.0  # [m] the lane offset counted at most (and off the lanes, where the
#   car's lane has no centre)
FAIL_PENALTY = 100.0  # [m] lost once when a criterion fails, the car touches something or
#   the run ends in error


@dataclass(frozen=True, slots=True)
class StepOutcome:
    """What the reward is computed from, for one step (truth)."""

    progress: float  # [m] along the route over the step
    lane_error: float  # [m] centre offset from its lane's centre at the step's end
    dt: float  # [s] the step's duration
    accel_change: float  # [m/s^2] asked acceleration minus the last step's
    failed: bool  # a criterion failed, a contact, or an error, at this step


def reward(o: StepOutcome) -> float:
    """The step's reward (module doc) [m]."""
    lane = min(abs(o.lane_error), MAX_LANE_ERROR) if math.isfinite(o.lane_error) \
        else MAX_LANE_ERROR
    r = o.progress - LANE_WEIGHT * lane * o.dt - JERK_WEIGHT * abs(o.accel_change)
    return r - FAIL_PENALTY if o.failed else r
