"""Where the lateral reference comes from: the camera's lane, or the map when it is lost.

An enum FSM with a pure transition function (table-tested):

| from         | to           | when                                                     |
|--------------|--------------|----------------------------------------------------------|
| ACQUIRING    | CAMERA       | confidence >= `acquire` (the first good lane estimate)   |
| ACQUIRING    | MAP_HOLD     | no good estimate `acquire_time` after the start          |
| CAMERA       | MAP_HOLD     | confidence < `lose` (hysteresis: `lose` < `acquire`)     |
| MAP_HOLD     | CAMERA       | confidence >= `acquire` again                            |
| MAP_HOLD     | STOP_IN_LANE | lost for `stop_after` seconds                            |
| STOP_IN_LANE | CAMERA       | confidence >= `acquire` again                            |
| any but MAP  | JUNCTION     | near a town junction (no lines inside; the map's turn path) |
| JUNCTION     | CAMERA       | past the junction, confidence >= `acquire`               |
| JUNCTION     | ACQUIRING    | past the junction, no good estimate yet                  |

MAP is the state of a stack built without a camera (GNSS + odometry on the HD map only):
it never changes. ACQUIRING follows the map lane at the planned speed (the camera's first
estimate arrives one sensor period after the start). MAP_HOLD follows the map lane with the
localisation estimate (GNSS + odometry) and slows to `hold_speed`; STOP_IN_LANE brings the
car to a stop in its lane. JUNCTION follows the map's path through a town junction at the
planned speed: its lines end at the junction's mouth, and the path turns where none are
painted. Every change carries a reason for the log.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass


class LaneSource(enum.Enum):
    MAP = "map"
    ACQUIRING = "acquiring"
    CAMERA = "camera"
    MAP_HOLD = "map_hold"
    STOP_IN_LANE = "stop_in_lane"
    JUNCTION = "junction"


@dataclass(frozen=True, slots=True)
class LaneSourceParams:
    acquire: float = 0.5  # [-] confidence to take (or take back) the camera's lane
    lose: float = 0.3  # [-] confidence below which the camera's lane is lost
    acquire_time: float = 1.0  # [s] from the start, to find the lane before holding
    stop_after: float = 5.0  # [s] lost this long: stop in lane
    hold_speed: float = 20.0 / 3.6  # [m/s] speed while holding the lane on the map


@dataclass(frozen=True, slots=True)
class LaneSourceInput:
    t: float  # [s] now
    confidence: float  # [-] of the latest lane estimate (0 when there is none)
    since: float  # [s] time of the last change of state (the start, for ACQUIRING)
    junction: bool = False  # the car is near a town junction (`LaneKeepingPlanner`)


@dataclass(frozen=True, slots=True)
class Change:
    to: LaneSource
    reason: str


def transition(state: LaneSource, x: LaneSourceInput, p: LaneSourceParams) -> Change | None:
    """The change of state for input `x`, or None to stay."""
    good = x.confidence >= p.acquire
    if state is LaneSource.MAP:
        return None
    if state is LaneSource.JUNCTION:
        return None if x.junction else _past_junction(good, x.confidence)
    if x.junction:
        return Change(LaneSource.JUNCTION, "at a junction: the map's path")
    if state is LaneSource.CAMERA:
        if x.confidence < p.lose:
            return Change(LaneSource.MAP_HOLD,
                          f"lane confidence {x.confidence:.2f} < {p.lose}: holding on the map")
        return None
    if good:
        return Change(LaneSource.CAMERA, f"lane found (confidence {x.confidence:.2f})")
    if state is LaneSource.ACQUIRING and x.t - x.since >= p.acquire_time:
        return Change(LaneSource.MAP_HOLD, f"no lane found in {p.acquire_time:.1f} s")
    if state is LaneSource.MAP_HOLD and x.t - x.since >= p.stop_after:
        return Change(LaneSource.STOP_IN_LANE,
                      f"lane lost for {p.stop_after:.1f} s: stopping in lane")
    return None


def _past_junction(good: bool, confidence: float) -> Change:
    if good:
        return Change(LaneSource.CAMERA, f"past the junction, lane found "
                                         f"(confidence {confidence:.2f})")
    return Change(LaneSource.ACQUIRING, "past the junction: looking for the lane")
