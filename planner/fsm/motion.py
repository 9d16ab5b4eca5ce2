"""The motion FSM (ICCAS 2020's M-FSM): which manoeuvre the car is in.

States: LANE_KEEP, LANE_CHANGE_LEFT, LANE_CHANGE_RIGHT, TURN_RIGHT, TURN_LEFT, U_TURN. The
turns are entered from the route's command at a town junction (`planner.motion_layer`).

Inputs (`MotionInput`) are decided upstream from the tracks and the map
(`planner.lane_occupancy`): whether a slower vehicle blocks the lane ahead, whether the lanes
to the left and right are free ("according to the presence or absence of obstacles in the
side", ICCAS 2020), the lane the route needs, and the progress of the manoeuvre in hand.

A lane change is *committed* once the car's centre has crossed into the target lane: before
that, a target lane that stops being free aborts the change (back to LANE_KEEP in the origin
lane, `MotionChange.abort`); after it, finishing is the safer way out.

| from              | to                | when                                                  |
|-------------------|-------------------|-------------------------------------------------------|
| LANE_KEEP         | LANE_CHANGE_RIGHT | a flat tyre: pull over (right lane, then shoulder)    |
| LANE_KEEP         | TURN_RIGHT        | the route turns right at the junction being entered   |
| LANE_KEEP         | TURN_LEFT         | the route turns left there                            |
| LANE_KEEP         | U_TURN            | the route turns back there                            |
| LANE_KEEP         | LANE_CHANGE_RIGHT | the route needs a lane to the right and it is free    |
| LANE_KEEP         | LANE_CHANGE_LEFT  | the route needs a lane to the left and it is free     |
| LANE_KEEP         | LANE_CHANGE_LEFT  | overtaking allowed, the lane blocked, the left free   |
| LANE_KEEP         | LANE_CHANGE_RIGHT | overtaking allowed, the lane blocked, only the right free
| LANE_CHANGE_LEFT  | LANE_KEEP         | the change is done (in the target lane)               |
| LANE_CHANGE_LEFT  | LANE_KEEP (abort) | the target lane is no longer free, not yet committed  |
| LANE_CHANGE_RIGHT | LANE_KEEP         | the change is done                                    |
| LANE_CHANGE_RIGHT | LANE_KEEP (abort) | the target lane is no longer free, not yet committed  |
| TURN_RIGHT, TURN_LEFT, U_TURN | LANE_KEEP | the turn is done (in the exit lane)           |

Rows are tried top to bottom. A flat tyre comes first and stops everything else: the car
moves right lane by lane (`right_free` then means the next lane, or the paved shoulder from
lane 0) and stays on the shoulder. Out of LANE_KEEP, route needs come before overtaking, and
overtaking waits `keep_time` after the last change (no weaving); a route lane change waits
`route_keep_time` only.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass


class Motion(enum.Enum):
    LANE_KEEP = "lane_keep"
    LANE_CHANGE_LEFT = "lane_change_left"
    LANE_CHANGE_RIGHT = "lane_change_right"
    TURN_RIGHT = "turn_right"
    TURN_LEFT = "turn_left"
    U_TURN = "u_turn"


class Turn(enum.Enum):
    """The route's command at a junction."""

    RIGHT = "right"
    LEFT = "left"
    U_TURN = "u_turn"


LANE_CHANGES = frozenset({Motion.LANE_CHANGE_LEFT, Motion.LANE_CHANGE_RIGHT})
TURNS = frozenset({Motion.TURN_RIGHT, Motion.TURN_LEFT, Motion.U_TURN})
_TURN_STATE = {Turn.RIGHT: Motion.TURN_RIGHT, Turn.LEFT: Motion.TURN_LEFT,
               Turn.U_TURN: Motion.U_TURN}


@dataclass(frozen=True, slots=True)
class MotionParams:
    keep_time: float = 3.0  # [s] least time since the last change before overtaking
    route_keep_time: float = 1.0  # [s] least time since the last change before a route change


@dataclass(frozen=True, slots=True)
class MotionInput:
    t: float  # [s]
    since: float  # [s] time of the last motion change (-inf before any)
    overtake: bool = False  # the driver allows lane changes to pass slower vehicles
    blocked: bool = False  # a slower vehicle blocks the lane ahead (debounced upstream)
    left_free: bool = False  # a lane to the left exists and is free by the tracks
    right_free: bool = False  # a lane to the right exists and is free by the tracks
    route_lane: int = 0  # lanes the route needs to move: > 0 left, < 0 right, 0 none
    target_free: bool = True  # the target lane of the change in hand is still free
    committed: bool = False  # the car's centre is in the target lane of the change
    change_done: bool = False  # the lane change's path is finished
    turn: Turn | None = None  # the route's command at the junction being entered
    turn_done: bool = False  # the turn's path is finished
    pull_over: bool = False  # a flat tyre: get onto the shoulder


@dataclass(frozen=True, slots=True)
class MotionChange:
    to: Motion
    reason: str
    abort: bool = False  # a lane change given up: back in the origin lane


def transition(state: Motion, x: MotionInput, p: MotionParams) -> MotionChange | None:
    """The change of state for input `x`, or None to stay (see the module doc's table)."""
    if state is Motion.LANE_KEEP:
        return _from_lane_keep(x, p)
    if state in LANE_CHANGES:
        if x.change_done:
            return MotionChange(Motion.LANE_KEEP, "in the target lane")
        if not x.target_free and not x.committed:
            return MotionChange(Motion.LANE_KEEP, "the target lane is no longer free: abort",
                                abort=True)
        return None
    if x.turn_done:
        return MotionChange(Motion.LANE_KEEP, "the turn is done")
    return None


def _from_lane_keep(x: MotionInput, p: MotionParams) -> MotionChange | None:
    if x.pull_over:
        if x.right_free and x.t - x.since >= p.route_keep_time:
            return MotionChange(Motion.LANE_CHANGE_RIGHT, "a flat tyre: pull over")
        return None
    if x.turn is not None:
        return MotionChange(_TURN_STATE[x.turn], f"the route turns {x.turn.value} here")
    waited = x.t - x.since
    if x.route_lane and waited >= p.route_keep_time:
        if x.route_lane < 0 and x.right_free:
            return MotionChange(Motion.LANE_CHANGE_RIGHT, "the route needs a lane to the right")
        if x.route_lane > 0 and x.left_free:
            return MotionChange(Motion.LANE_CHANGE_LEFT, "the route needs a lane to the left")
        return None  # wait in lane for the gap: do not overtake away from the route
    if not (x.overtake and x.blocked) or waited < p.keep_time:
        return None
    if x.left_free:
        return MotionChange(Motion.LANE_CHANGE_LEFT, "a slower vehicle ahead, the left lane free")
    if x.right_free:
        return MotionChange(Motion.LANE_CHANGE_RIGHT,
                            "a slower vehicle ahead, only the right lane free")
    return None
