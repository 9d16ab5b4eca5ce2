"""The motion FSM (ICCAS 2020's M-FSM): which manoeuvre the car is in.

States: LANE_KEEP, LANE_CHANGE_LEFT, LANE_CHANGE_RIGHT, TURN_RIGHT, TURN_LEFT, U_TURN. The
turns are entered from the route's command at a town junction (`planner.motion_layer`).

Inputs (`MotionInput`) are decided upstream from the tracks and the map
(`planner.lane_occupancy`, `planner.motion_layer`): whether a slower vehicle blocks the lane
ahead, whether the lanes to the left and right are free ("according to the presence or
absence of obstacles in the side", ICCAS 2020; rear traffic included: UN R157's rule that a
vehicle approaching from behind in the target lane need not brake harder than 3 m/s^2, which
so guards every lateral move: a pass, a flat tyre's pull-over, a route change before an exit,
keeping right), whether a pass path to either side would clear the vehicle ahead, whether
the whole pass (out, past and back in) would be over before a vehicle coming up behind in
that lane, not braking, is nearer than the rear rule's distance (`planner.rear_pass`), the
lanes the route needs the car to move, the route's turn at a junction, a flat tyre's
pull-over, the lane the driver's turn-signal stalk asks for, whether a pass through the
oncoming lane is safe (`planner.oncoming_pass`),
whether the car keeps the oncoming lane and may take its own lane back, and the progress of
the manoeuvre in hand.

A lane change is *committed* once the car's centre is inside the target lane: before that,
a target lane that stops being free aborts the change (a change to LANE_KEEP before the
change is done, back to the origin lane); after it, finishing is the safer way out.

Transitions (`TABLE`, as data). For the state the car is in, the rows that leave it are
tried in this order and the first that holds is taken:

1. lane_keep -> lane_change_right: back from the oncoming lane as soon as the own lane may
   be taken: the vehicle passed is a safe gap behind, or the pass became unsafe before the
   car drew alongside it (no `keep_time`)
2. lane_keep -> lane_change_right: a flat tyre: pull over (right lane, then shoulder), once
   `route_keep_time` has passed and the lane to the right is free
3. lane_keep -> turn_right: the route turns right at the junction being entered
4. lane_keep -> turn_left: the route turns left there
5. lane_keep -> u_turn: the route turns back there
6. lane_keep -> lane_change_right: the route needs a lane to the right and it is free
7. lane_keep -> lane_change_left: the route needs a lane to the left and it is free
8. lane_keep -> lane_change_right: the driver's turn signal asks for a lane to the right, it
   is free, the route needs no other lane and `route_keep_time` has passed
9. lane_keep -> lane_change_left: the driver's turn signal asks for a lane to the left (as
   above)
10. lane_keep -> lane_change_left: overtaking allowed, the lane blocked, the left free, a
    pass path into it clears the vehicle ahead and the whole pass outruns every vehicle
    coming up behind in the left lane, `keep_time` since the last change, and neither the
    route nor the driver asks for another lane
11. lane_keep -> lane_change_right: overtaking allowed, the lane blocked, only the right
    free, clearing and outrun (as above)
12. lane_keep -> lane_change_left: overtaking allowed, the lane blocked, the only way past
    the oncoming lane and a pass through it safe (`planner.oncoming_pass`) on a path that
    clears the vehicle ahead, `keep_time` since the last change, and neither the route nor
    the driver asks for another lane
13. lane_keep -> lane_change_right: keep right: overtaking allowed, the lane not blocked,
    the right free and clear (nothing slower ahead in it to block it), `keep_time` since the
    last change (none when a faster vehicle comes up behind), and neither the route nor the
    driver asks for another lane
14. lane_change_left, lane_change_right -> lane_keep: the change is done (in the target
    lane)
15. lane_change_left, lane_change_right -> lane_keep: abort: the target lane is no longer
    free, not yet committed
16. turn_right, turn_left, u_turn -> lane_keep: the turn is done (in the exit lane)

In the oncoming lane (after a pass through it on a road with one lane each way) nothing
but the way back is taken, and it is taken as soon as it may be: the car never stays there
longer than needed. A change into the oncoming lane is committed once the car has drawn
alongside the vehicle it passes (before that, an oncoming vehicle that makes the pass unsafe
aborts it: back behind the vehicle).

A flat tyre comes first among the rest and stops everything else out of LANE_KEEP: the car
moves right lane by lane (`right_free` then means the next lane, or the paved shoulder from
lane 0) and stays on the shoulder. Then the route's turns, then its lane needs, then
overtaking, then keeping right: where the driver lets the car change lanes to pass, it goes
back to the right once that lane is free and clear (no slower vehicle ahead in it within the
ACC's d_max, which would make it pass again). A blocked lane is passed also from a
standstill behind a stopped vehicle: `blocked` does not ask that the vehicle ahead moves,
only that it is slower than wanted; while no side is free, or a pass path would not clear
it, or a faster vehicle coming up behind in the lane beside would reach the car before the
pass is over, the car waits in its lane (the ACC stops it behind that vehicle, or it follows
it) and goes once all hold. Overtaking and keeping right wait `keep_time` after the last
change (no weaving); a route lane change waits `route_keep_time` only. Keeping right with a
faster vehicle coming up behind in the lane kept (`yield_behind`) waits no `keep_time`: the
car leaves the lane to it as soon as the right lane is free and clear, rather than linger in
its way after a pass.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from planner.fsm.machine import Row, Table, Transition, fired_row, next_state, render


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
    right_clear: bool = False  # ... and nothing slower ahead in it would block it
    yield_behind: bool = False  # a faster vehicle comes up behind in the lane kept: keeping
    #   right waits no `keep_time`
    clears_left: bool = True  # a pass path into the left lane clears the vehicle ahead
    clears_right: bool = True  # ... into the right lane
    outruns_left: bool = True  # a pass into the left lane is over, the car back in its
    #   lane, with every vehicle coming up behind in it (at its speed, not braking) still
    #   UN R157's rear distance back (`planner.rear_pass`)
    outruns_right: bool = True  # ... into the right lane
    route_lane: int = 0  # [lanes] the route needs the car to move: > 0 left, < 0 right
    driver_lane: int = 0  # [lanes] the driver's turn-signal stalk asks the car to move:
    #   > 0 left, < 0 right (the stack changes lanes when its own rules allow)
    target_free: bool = True  # the target lane of the change in hand is still free
    committed: bool = False  # the car's centre is in the target lane of the change
    change_done: bool = False  # the lane change's path is finished
    turn: Turn | None = None  # the route's command at the junction being entered
    turn_done: bool = False  # the turn's path is finished
    pull_over: bool = False  # a flat tyre: get onto the shoulder
    oncoming_pass: bool = False  # the only way past is the oncoming lane, a pass through it
    #   is safe now (`planner.oncoming_pass`) and its path clears the vehicle ahead
    in_oncoming: bool = False  # the car keeps the oncoming lane (a pass under way)
    back_free: bool = False  # ... and may take its own lane back: the vehicle passed is a
    #   safe gap behind, or the pass became unsafe before the car drew alongside it


def _waited(x: MotionInput) -> float:
    """[s] since the last motion change."""
    return x.t - x.since


def _route_holds(x: MotionInput, p: MotionParams) -> bool:
    """The route needs another lane now: the car waits for it rather than overtake away."""
    return bool(x.route_lane) and _waited(x) >= p.route_keep_time


def _free_to_choose(x: MotionInput) -> bool:
    """No flat tyre, no turn, not in the oncoming lane: the route and overtaking may move
    the car."""
    return not x.pull_over and x.turn is None and not x.in_oncoming


def _back_from_oncoming(_m: Motion, x: MotionInput, _p: MotionParams) -> bool:
    return x.in_oncoming and x.back_free


def _pull_over(_m: Motion, x: MotionInput, p: MotionParams) -> bool:
    return x.pull_over and x.right_free and _waited(x) >= p.route_keep_time


class _Turns:
    def __init__(self, turn: Turn) -> None:
        self.turn = turn

    def __call__(self, _m: Motion, x: MotionInput, _p: MotionParams) -> bool:
        return not x.pull_over and x.turn is self.turn


def _route_right(_m: Motion, x: MotionInput, p: MotionParams) -> bool:
    return _free_to_choose(x) and _route_holds(x, p) and x.route_lane < 0 and x.right_free


def _route_left(_m: Motion, x: MotionInput, p: MotionParams) -> bool:
    return _free_to_choose(x) and _route_holds(x, p) and x.route_lane > 0 and x.left_free


def _driver_asks(x: MotionInput, p: MotionParams) -> bool:
    """The driver's stalk asks for another lane, the route needs none, no flat tyre, turn
    or pass in the oncoming lane, and `route_keep_time` has passed since the last change."""
    return (_free_to_choose(x) and not _route_holds(x, p) and bool(x.driver_lane)
            and _waited(x) >= p.route_keep_time)


def _driver_right(_m: Motion, x: MotionInput, p: MotionParams) -> bool:
    return _driver_asks(x, p) and x.driver_lane < 0 and x.right_free


def _driver_left(_m: Motion, x: MotionInput, p: MotionParams) -> bool:
    return _driver_asks(x, p) and x.driver_lane > 0 and x.left_free


def _may_overtake(x: MotionInput, p: MotionParams) -> bool:
    return (_free_to_choose(x) and not _route_holds(x, p) and not x.driver_lane
            and x.overtake and x.blocked and _waited(x) >= p.keep_time)


def _overtake_left(_m: Motion, x: MotionInput, p: MotionParams) -> bool:
    return _may_overtake(x, p) and x.left_free and x.clears_left and x.outruns_left


def _overtake_right(_m: Motion, x: MotionInput, p: MotionParams) -> bool:
    return _may_overtake(x, p) and x.right_free and x.clears_right and x.outruns_right


def _overtake_oncoming(_m: Motion, x: MotionInput, p: MotionParams) -> bool:
    return _may_overtake(x, p) and x.oncoming_pass


def _keep_right(_m: Motion, x: MotionInput, p: MotionParams) -> bool:
    return (_free_to_choose(x) and not _route_holds(x, p) and not x.driver_lane
            and x.overtake and not x.blocked and x.right_free and x.right_clear
            and (_waited(x) >= p.keep_time or x.yield_behind))


def _change_done(_m: Motion, x: MotionInput, _p: MotionParams) -> bool:
    return x.change_done


def _abort(_m: Motion, x: MotionInput, _p: MotionParams) -> bool:
    return not x.target_free and not x.committed


def _turn_done(_m: Motion, x: MotionInput, _p: MotionParams) -> bool:
    return x.turn_done


M = Motion
_KEEP = frozenset({M.LANE_KEEP})

TABLE: Table[Motion, MotionInput, MotionParams] = Table(Motion, (
    Row(_KEEP, M.LANE_CHANGE_RIGHT, _back_from_oncoming,
        "back from the oncoming lane as soon as the own lane may be taken: the vehicle "
        "passed is a safe gap behind, or the pass became unsafe before the car drew "
        "alongside it (no `keep_time`)", "back from the oncoming lane"),
    Row(_KEEP, M.LANE_CHANGE_RIGHT, _pull_over,
        "a flat tyre: pull over (right lane, then shoulder), once `route_keep_time` has "
        "passed and the lane to the right is free", "a flat tyre: pull over"),
    Row(_KEEP, M.TURN_RIGHT, _Turns(Turn.RIGHT),
        "the route turns right at the junction being entered", "the route turns right here"),
    Row(_KEEP, M.TURN_LEFT, _Turns(Turn.LEFT), "the route turns left there",
        "the route turns left here"),
    Row(_KEEP, M.U_TURN, _Turns(Turn.U_TURN), "the route turns back there",
        "the route turns u_turn here"),
    Row(_KEEP, M.LANE_CHANGE_RIGHT, _route_right,
        "the route needs a lane to the right and it is free",
        "the route needs a lane to the right"),
    Row(_KEEP, M.LANE_CHANGE_LEFT, _route_left,
        "the route needs a lane to the left and it is free",
        "the route needs a lane to the left"),
    Row(_KEEP, M.LANE_CHANGE_RIGHT, _driver_right,
        "the driver's turn signal asks for a lane to the right, it is free, the route needs "
        "no other lane and `route_keep_time` has passed",
        "the driver asks for a lane to the right"),
    Row(_KEEP, M.LANE_CHANGE_LEFT, _driver_left,
        "the driver's turn signal asks for a lane to the left (as above)",
        "the driver asks for a lane to the left"),
    Row(_KEEP, M.LANE_CHANGE_LEFT, _overtake_left,
        "overtaking allowed, the lane blocked, the left free, a pass path into it clears "
        "the vehicle ahead and the whole pass outruns every vehicle coming up behind in the "
        "left lane, `keep_time` since the last change, and neither the route nor the "
        "driver asks for another lane",
        "a slower vehicle ahead, the left lane free"),
    Row(_KEEP, M.LANE_CHANGE_RIGHT, _overtake_right,
        "overtaking allowed, the lane blocked, only the right free, clearing and outrun "
        "(as above)",
        "a slower vehicle ahead, only the right lane free"),
    Row(_KEEP, M.LANE_CHANGE_LEFT, _overtake_oncoming,
        "overtaking allowed, the lane blocked, the only way past the oncoming lane and a "
        "pass through it safe (`planner.oncoming_pass`) on a path that clears the vehicle "
        "ahead, `keep_time` since the last change, and neither the route nor the "
        "driver asks for another lane",
        "a slower vehicle ahead, a pass through the oncoming lane is safe"),
    Row(_KEEP, M.LANE_CHANGE_RIGHT, _keep_right,
        "keep right: overtaking allowed, the lane not blocked, the right free and clear "
        "(nothing slower ahead in it to block it), `keep_time` since the last change (none "
        "when a faster vehicle comes up behind), and neither the route nor the "
        "driver asks for another lane",
        "keep right: the right lane is free"),
    Row(LANE_CHANGES, M.LANE_KEEP, _change_done, "the change is done (in the target lane)",
        "in the target lane"),
    Row(LANE_CHANGES, M.LANE_KEEP, _abort,
        "abort: the target lane is no longer free, not yet committed",
        "the target lane is no longer free: abort"),
    Row(TURNS, M.LANE_KEEP, _turn_done, "the turn is done (in the exit lane)",
        "the turn is done"),
))


def transition(state: Motion, x: MotionInput, p: MotionParams) -> Transition[Motion] | None:
    """The change of state for input `x`, or None to stay (`TABLE`)."""
    return next_state(TABLE, state, x, p)


PASSES = frozenset({_overtake_left, _overtake_right, _overtake_oncoming})  # the rows' guards
#   of a change to pass


def is_pass(state: Motion, x: MotionInput, p: MotionParams) -> bool:
    """Whether the change taken from `state` for input `x` is one to pass a slower vehicle
    (an overtaking row), not one the route or a flat tyre asks for."""
    row = fired_row(TABLE, state, x, p)
    return row is not None and row.guard in PASSES


if __name__ == "__main__":  # print the table for the module doc
    print(render(TABLE))
