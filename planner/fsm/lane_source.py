"""Where the lateral reference comes from: the camera's lane, or the map when it is lost.

Inputs (`LaneSourceInput`): the time t [s], the confidence [-] of the latest lane estimate,
the boundaries (`lines`) the latest frame saw, the age [s] of the last measurement of the
lane (the lane filter's dead reckoning since, `perception.lanes.LaneFilter`), the time [s]
the state was entered, whether the car is near a town junction and whether the camera's
lane is another than the lane kept (its offset more than `camera_agree` from the map's
lane kept at the frame's pose: a lane change just ended and the camera still sees the lane
left, or a misdetection; with the pose corrected by the camera's lane on the map,
`perception.localization`, a GNSS bias no longer makes them disagree). Transitions
(`TABLE`, as data): for the state it is in, the rows that leave it are tried in this order
and the first that holds is taken:

1. junction -> camera: past the junction, confidence >= `acquire` of the lane kept
2. junction -> acquiring: past the junction, no good estimate yet
3. acquiring, camera, one_line, map_hold, stop_in_lane -> junction: near a town junction (no
   lines inside; the map's turn path)
4. acquiring, camera, one_line -> map_hold: the camera's frames are faulty
   (`perception.health`)
5. camera -> one_line: confidence < `lose`, a line still seen, the last measurement younger
   than `dead_reckon_time`
6. camera -> map_hold: confidence < `lose` (hysteresis: `lose` < `acquire`)
7. camera, one_line -> acquiring: the camera's lane is not the lane kept
8. one_line -> camera: confidence >= `acquire` of the lane kept
9. one_line -> map_hold: the lane not measured for `dead_reckon_time`
10. acquiring, map_hold, stop_in_lane -> camera: confidence >= `acquire` (a good lane
    estimate) of the lane kept
11. acquiring -> map_hold: no good estimate of the lane kept for `acquire_time`
12. map_hold -> stop_in_lane: lost for `stop_after` seconds of moving (standing, as in a
    queue, does not count)

What each state follows (`planner.planner`): MAP is the state of a stack built without a
camera (GNSS + odometry on the HD map only); no row leaves it. ACQUIRING follows the map
lane at the planned speed: the camera's first estimate arrives one sensor period after the
start (until it has corrected the pose across the lane, the line through the car parallel
to the lane), and after a lane change the camera may still see the lane left for a moment.
CAMERA follows the camera's lane, the lane kept. ONE_LINE follows it too, at the planned
speed, where the camera sees fewer lines than CAMERA needs (one hidden by a truck beside
the car, worn paint, a dashed line's one dash in view): the lane is the seen line and the
lane's width (the HD map's, `perception.lanes.LaneDetector.detect`), and between
measurements the filter dead-reckons its last fitted lane on odometry, for at most
`dead_reckon_time`. A camera that sees no line at all (black frames) goes from CAMERA
straight to MAP_HOLD. So does a camera whose frames the sensor-health monitor finds faulty
(`perception.health`: a blank, frozen or missing frame, which is then not perceived), and no
lane is taken from it (`acquire` needs a camera without a fault) until its frames are sound
again; the change's reason says how the fault was noticed. MAP_HOLD follows the map lane
placed by the localisation estimate (odometry, GNSS and the camera's lane as long as it was
seen) and slows to `hold_speed`; the time it has to find the lane again counts only while
the car moves (`standing`): standing a few metres behind a car in a queue, the camera sees
no line past it, and the car holds, to follow the queue off on the map until the lines are
in view again, not to stop in lane with its hazard lights on. STOP_IN_LANE brings the car
to a stop in its lane (with the hazard lights on, `planner.fsm.hazard`), until the lane is
found again. JUNCTION follows
the map's path through a town junction at the planned speed: the painted lines end at the
junction's mouth, and the path turns where none are painted. Every change carries a reason
for the log.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from planner.fsm.machine import Row, Table, Transition, next_state, render
from world.frames import kph


class LaneSource(enum.Enum):
    MAP = "map"
    ACQUIRING = "acquiring"
    CAMERA = "camera"
    ONE_LINE = "one_line"
    MAP_HOLD = "map_hold"
    STOP_IN_LANE = "stop_in_lane"
    JUNCTION = "junction"


@dataclass(frozen=True, slots=True)
class LaneSourceParams:
    acquire: float = 0.5  # [-] confidence to take (or take back) the camera's lane
    lose: float = 0.3  # [-] confidence below which the camera's lane is lost
    acquire_time: float = 1.0  # [s] ACQUIRING this long without a lane: hold on the map
    stop_after: float = 5.0  # [s] MAP_HOLD this long: stop in lane
    hold_speed: float = kph(20.0)  # [m/s] speed while holding the lane on the map
    standing_speed: float = 0.1  # [m/s] slower than this the car stands: a lane lost while
    #   it stands (its view of the lines blocked by the car it queues behind) is no reason
    #   to stop in lane: MAP_HOLD's `stop_after` counts only the time it moves
    dead_reckon_time: float = 1.0  # [s] ONE_LINE keeps a lane measured no longer ago (60 km/h:
    #   17 m, two 12 m periods of a dashed line; the odometry's heading drifts little in it)


@dataclass(frozen=True, slots=True)
class LaneSourceInput:
    t: float  # [s] now
    confidence: float  # [-] of the latest lane estimate (0 when there is none)
    since: float  # [s] when the state was entered (the first tick, for the initial one)
    junction: bool = False  # the car is near a town junction (`Planner.near_junction`)
    other_lane: bool = False  # the camera's lane is not the lane kept (module doc)
    lines: int = 0  # [-] boundaries the latest frame saw (0, 1, 2)
    age: float = math.inf  # [s] since the lane was last measured (dead-reckoned since)
    camera_fault: str | None = None  # how a fault of the camera was noticed in its frames
    #   (`perception.health`: blank, frozen, missing); None while it is fine
    standing: float = 0.0  # [s] the car has stood (odometry below `standing_speed`) since
    #   the state was entered


def _good(x: LaneSourceInput, p: LaneSourceParams) -> bool:
    return x.confidence >= p.acquire and x.camera_fault is None


def _camera_fault(_s: LaneSource, x: LaneSourceInput, _p: LaneSourceParams) -> bool:
    return x.camera_fault is not None


def _past_found(_s: LaneSource, x: LaneSourceInput, p: LaneSourceParams) -> bool:
    return not x.junction and _good(x, p) and not x.other_lane


def _past(_s: LaneSource, x: LaneSourceInput, _p: LaneSourceParams) -> bool:
    return not x.junction


def _at_junction(_s: LaneSource, x: LaneSourceInput, _p: LaneSourceParams) -> bool:
    return x.junction


def _lost(_s: LaneSource, x: LaneSourceInput, p: LaneSourceParams) -> bool:
    return x.confidence < p.lose


def _one_line(_s: LaneSource, x: LaneSourceInput, p: LaneSourceParams) -> bool:
    return x.confidence < p.lose and x.lines >= 1 and x.age < p.dead_reckon_time


def _not_measured(_s: LaneSource, x: LaneSourceInput, p: LaneSourceParams) -> bool:
    return x.age >= p.dead_reckon_time


def _found(_s: LaneSource, x: LaneSourceInput, p: LaneSourceParams) -> bool:
    return _good(x, p) and not x.other_lane


def _other_lane(_s: LaneSource, x: LaneSourceInput, _p: LaneSourceParams) -> bool:
    return x.other_lane


def _nothing_found(_s: LaneSource, x: LaneSourceInput, p: LaneSourceParams) -> bool:
    return x.t - x.since >= p.acquire_time


def _lost_too_long(_s: LaneSource, x: LaneSourceInput, p: LaneSourceParams) -> bool:
    return x.t - x.since - x.standing >= p.stop_after


L = LaneSource
_SEEKING = frozenset({L.ACQUIRING, L.MAP_HOLD, L.STOP_IN_LANE})  # looking for the lane

TABLE: Table[LaneSource, LaneSourceInput, LaneSourceParams] = Table(LaneSource, (
    Row(frozenset({L.JUNCTION}), L.CAMERA, _past_found,
        "past the junction, confidence >= `acquire` of the lane kept",
        lambda x, p: f"past the junction, lane found (confidence {x.confidence:.2f})"),
    Row(frozenset({L.JUNCTION}), L.ACQUIRING, _past, "past the junction, no good estimate yet",
        "past the junction: looking for the lane"),
    Row(_SEEKING | {L.CAMERA, L.ONE_LINE}, L.JUNCTION, _at_junction,
        "near a town junction (no lines inside; the map's turn path)",
        "at a junction: the map's path"),
    Row(frozenset({L.ACQUIRING, L.CAMERA, L.ONE_LINE}), L.MAP_HOLD, _camera_fault,
        "the camera's frames are faulty (`perception.health`)",
        lambda x, p: f"{x.camera_fault}: holding on the map"),
    Row(frozenset({L.CAMERA}), L.ONE_LINE, _one_line,
        "confidence < `lose`, a line still seen, the last measurement younger than "
        "`dead_reckon_time`",
        lambda x, p: f"lane confidence {x.confidence:.2f} < {p.lose}, {x.lines} line(s) "
        "seen: keeping the lane on them"),
    Row(frozenset({L.CAMERA}), L.MAP_HOLD, _lost,
        "confidence < `lose` (hysteresis: `lose` < `acquire`)",
        lambda x, p: f"lane confidence {x.confidence:.2f} < {p.lose}: holding on the map"),
    Row(frozenset({L.CAMERA, L.ONE_LINE}), L.ACQUIRING, _other_lane,
        "the camera's lane is not the lane kept",
        "the camera sees another lane than the one kept: the map's lane"),
    Row(frozenset({L.ONE_LINE}), L.CAMERA, _found,
        "confidence >= `acquire` of the lane kept",
        lambda x, p: f"both lines again (confidence {x.confidence:.2f})"),
    Row(frozenset({L.ONE_LINE}), L.MAP_HOLD, _not_measured,
        "the lane not measured for `dead_reckon_time`",
        lambda x, p: f"no line seen for {x.age:.1f} s: holding on the map"),
    Row(_SEEKING, L.CAMERA, _found,
        "confidence >= `acquire` (a good lane estimate) of the lane kept",
        lambda x, p: f"lane found (confidence {x.confidence:.2f})"),
    Row(frozenset({L.ACQUIRING}), L.MAP_HOLD, _nothing_found,
        "no good estimate of the lane kept for `acquire_time`",
        lambda x, p: f"no lane found in {p.acquire_time:.1f} s"),
    Row(frozenset({L.MAP_HOLD}), L.STOP_IN_LANE, _lost_too_long,
        "lost for `stop_after` seconds of moving (standing, as in a queue, does not count)",
        lambda x, p: f"lane lost for {p.stop_after:.1f} s: stopping in lane"),
))


def transition(state: LaneSource, x: LaneSourceInput,
               p: LaneSourceParams) -> Transition[LaneSource] | None:
    """The change of state for input `x`, or None to stay (`TABLE`)."""
    return next_state(TABLE, state, x, p)


if __name__ == "__main__":  # print the table for the module doc
    print(render(TABLE))
