"""The motion FSM in the planner: lane occupancy in, the lane to keep and the path out.

Positions are stations s [m] along the route's reference line and lateral offsets d [m]
from it (left +); lanes are ego-direction lane indices (0 rightmost, `SHOULDER` the paved
shoulder). Per tick:

1. the tracks are placed in the lane kept, the origin lane and the neighbours that go on
   for a whole change (`planner.lane_occupancy`), and the shoulder when a flat tyre pulls
   the car over from lane 0;
2. the inputs of the motion FSM (`planner.fsm.motion`): the lane kept is *blocked* once a
   slower vehicle has blocked it for ``blocked_time``; the lanes left and right are free or
   not; the route needs the car to move right when the lane kept does not go on to
   max(``prepare_distance``, ``prepare_time`` v) ahead (a lane that ends at an exit or a
   lane drop is left in time); the route's turn at a junction; during a change, whether
   the target lane is still free, whether the car's centre is inside it (committed) and
   whether the path is done;
3. the motion FSM steps once.

Entering a lane change makes the target lane the lane kept (its speed plan and, once done,
its camera lane) and plans the Hermite path into it from the car's pose
(`planner.lane_change_path`); the change is done when the car's station reaches the path's
end. An abort plans the same kind of path back to the origin lane, followed in LANE_KEEP
until its end. While a path is followed, the vehicle ahead in the lane kept (the target
lane) is the ACC's lead; the vehicle ahead in the origin lane is a lead too while the car's
body (mirrors included) still overlaps that lane (`leads`): the car does not run into the
vehicle it is leaving. On a pass (a change taken to pass a slower vehicle), the vehicle
passed counts only once it is near, within UN R157's d_min or under ``pass_ttc`` to
collision: the car does not trail it through the pass. A change the route or a flat tyre
asks for keeps trailing it (the car may be moving into that vehicle's path). Keeping right
after a pass waits for a car behind in the right lane to be ``keep_right_gap`` back (a
margin over the gap that aborts).

At a town junction where the route turns, the turn is entered when the car's centre passes
the stop line and done at the junction's exit (`RoadMap.junctions`); its path is the map's
lane 0, which turns along the junction's arc (`world.map.town`), so the path needs nothing
planned here. Lane 0 is the only lane through a turn: the route lane change brings the car
into it before the junction ("a lane ends ahead").
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from perception.messages import EgoState, Track
from planner.fsm.acc import AccParams, r157_min_gap
from planner.fsm.machine import Machine, StateChange
from planner.fsm.motion import (
    LANE_CHANGES,
    TURNS,
    Motion,
    MotionInput,
    MotionParams,
    Turn,
    is_pass,
    transition,
)
from planner.lane_change_path import LaneChangeParams, LaneChangePath, start_lane_change
from planner.lane_occupancy import (
    LaneTraffic,
    Neighbour,
    OccupancyParams,
    is_blocked,
    is_free,
    lane_traffic,
)
from world.frames import VehicleInfo
from world.hdmap import SHOULDER, Junction, RoadMap
from world.hdmap import Manoeuvre as JunctionManoeuvre


@dataclass(frozen=True, slots=True)
class MotionLayerParams:
    overtake: bool = False  # the driver allows lane changes to pass slower vehicles
    blocked_time: float = 1.0  # [s] blocked this long before it counts
    mirrors: float = 0.1  # [m] how far each mirror stands out beyond the body's side
    prepare_distance: float = 150.0  # [m] a lane ending this near ahead is left ...
    prepare_time: float = 12.0  # [s] ... or this many seconds ahead at the present speed
    pass_ttc: float = 4.0  # [s] during a change, the car being left is a lead once closer
    #   in time than this (or within d_min)
    keep_right_gap: float = 2.0  # [s] keeping right waits for this time gap to a car behind
    #   in the right lane (UN R157's t_G of 1 s aborts a change: the margin between the two
    #   keeps a gap that hovers near t_G from starting and aborting changes)
    motion: MotionParams = field(default_factory=MotionParams)
    occupancy: OccupancyParams = field(default_factory=OccupancyParams)
    lane_change: LaneChangeParams = field(default_factory=LaneChangeParams)


@dataclass(frozen=True, slots=True)
class Manoeuvre:
    """The motion layer's output for one tick."""

    motion: Motion
    lane: int  # [-] the lane kept, or moved into (ego-direction index, `SHOULDER`)
    origin: int  # [-] the lane left by a lane change in hand (== lane otherwise)
    path: LaneChangePath | None  # the lane-change (or abort) path being followed
    leads: tuple[Neighbour, ...] = ()  # on a path: the vehicles ahead in the lanes occupied


class MotionLayer:
    """Motion state, lane and lane-change path of one run."""

    def __init__(self, road: RoadMap, lane: int, acc: AccParams, vehicle: VehicleInfo,
                 params: MotionLayerParams | None = None) -> None:
        self.road, self.vehicle = road, vehicle
        self.acc = acc
        self.params = params if params is not None else MotionLayerParams()
        self.machine = Machine("motion", Motion.LANE_KEEP)
        self.lane = self.origin = lane
        self.path: LaneChangePath | None = None
        self._blocked_since: float | None = None
        self._turn_end = math.inf  # [m] where the turn in hand ends (its junction's exit)
        self._near: set[int] = set()  # tracks of the lane being left found near (`_leads`)
        self._passing = False  # the change in hand is one to pass a slower vehicle

    def update(self, ego: EgoState, v_want: float, tracks: Sequence[Track],
               pull_over: bool = False) -> tuple[Manoeuvre, tuple[StateChange, ...]]:
        """Step with the ego estimate, the speed it wants [m/s], the confirmed tracks and
        whether to pull over onto the shoulder (a flat tyre)."""
        s, d = (float(a) for a in self.road.local_coordinates((ego.x, ego.y)))
        lanes = self._lanes_around(s, ego.speed, pull_over)
        traffic = lane_traffic(self.road, tracks, ego.t, s, ego.speed, lanes,
                               self.params.occupancy, self.vehicle)
        x = self._input(ego, s, d, v_want, traffic, pull_over)
        change = transition(self.machine.state, x, self.params.motion)
        if change is not None:
            self._passing = is_pass(self.machine.state, x, self.params.motion)
            # a lane change given up before it was done: back to the origin lane
            abort = self.machine.state in LANE_CHANGES and not x.change_done
            self._enter(change.to, abort, ego, s, pull_over)
        elif self.path is not None and self.motion is Motion.LANE_KEEP and s >= self.path.end:
            self.path = None  # the way back after an abort is done
            self.origin = self.lane
        changes = self.machine.apply(ego.t, change)
        return Manoeuvre(self.motion, self.lane, self.origin, self.path,
                         self._leads(traffic, s, d, ego.speed)), changes

    @property
    def motion(self) -> Motion:
        return self.machine.state

    def _lanes_around(self, s: float, v: float, pull_over: bool) -> tuple[int, ...]:
        """The lane kept, the origin, the neighbours that go on for a whole change (at
        max(v, 5 m/s) for ``t_cap``), and the shoulder when pulling over from lane 0."""
        n_now = self.road.lanes_at(s)
        reach = min(s + max(v, 5.0) * self.params.lane_change.t_cap, self.road.length)
        n_later = self.road.lanes_at(reach)
        near = {self.lane, self.origin}
        if self.lane != SHOULDER:
            near.update(k for k in (self.lane - 1, self.lane + 1)
                        if 0 <= k < min(n_now, n_later))
        if self.lane == 0 and pull_over and self.road.shoulder.exists_at(s):
            near.add(SHOULDER)
        return tuple(sorted(near))

    @staticmethod
    def _right_of(lane: int, pull_over: bool) -> int:
        """The lane to the right of `lane`; from lane 0, the shoulder when pulling over."""
        return SHOULDER if lane == 0 and pull_over else lane - 1

    def _lanes_ahead(self, s: float, v: float) -> int:
        """The fewest ego-direction lanes from station `s` [m] to max(`prepare_distance`,
        `prepare_time` * `v`) ahead, `v` [m/s] (a lane that ends there, at an exit or a lane
        drop, must be left in time)."""
        end = s + max(self.params.prepare_distance, self.params.prepare_time * v)
        line = self.road.line
        first, last = (int(i) for i in line.segment_index(np.array([s, min(end, line.length)])))
        return min(self.road.sections[i].lanes for i in range(first, last + 1))

    def _input(self, ego: EgoState, s: float, d: float, v_want: float,
               traffic: dict[int, LaneTraffic], pull_over: bool) -> MotionInput:
        p, v, t = self.params, ego.speed, ego.t
        blocked_now = is_blocked(traffic[self.lane], v, v_want, p.occupancy, self.acc)
        if not blocked_now:
            self._blocked_since = None
        elif self._blocked_since is None:
            self._blocked_since = t
        blocked = self._blocked_since is not None and t - self._blocked_since >= p.blocked_time
        left = traffic.get(self.lane + 1) if self.lane != SHOULDER else None
        right = traffic.get(self._right_of(self.lane, pull_over)) \
            if self.lane != SHOULDER else None
        x = MotionInput(
            t=t, since=self.machine.since, overtake=p.overtake, blocked=blocked,
            left_free=left is not None and is_free(left, v, p.occupancy),
            right_free=right is not None and is_free(right, v, p.occupancy),
            right_clear=right is not None and right.lane != SHOULDER
            and not is_blocked(right, v, v_want, p.occupancy, self.acc)
            and (right.behind is None or right.behind.gap >= v * p.keep_right_gap),
            route_lane=min(self._lanes_ahead(s, v) - 1 - self.lane, 0),
            pull_over=pull_over and self.lane != SHOULDER,
            turn=_turn(self._junction_at(s)),
            turn_done=self.motion in TURNS and s >= self._turn_end,
        )
        if self.motion not in LANE_CHANGES or self.path is None:
            return x
        target = self.road.lane(self.lane)
        centre, width = float(target.offset_at(s)), float(target.width_at(s))
        return replace(x, target_free=is_free(traffic[self.lane], v, p.occupancy),
                       committed=abs(d - centre) < 0.5 * width, change_done=s >= self.path.end)

    def _junction_at(self, s: float) -> Junction | None:
        """The town junction whose stop line the car's centre has passed and whose exit it
        has not reached, where the route turns (None going straight, or elsewhere)."""
        for j in self.road.junctions:
            if j.s_stop <= s < j.s_exit and j.manoeuvre is not JunctionManoeuvre.STRAIGHT:
                return j
        return None

    def _enter(self, to: Motion, abort: bool, ego: EgoState, s: float,
               pull_over: bool) -> None:
        """Set the lane, origin and path for entering `to` (the machine itself changes
        after this)."""
        self._blocked_since = None
        if to in TURNS:
            junction = self._junction_at(s)
            assert junction is not None  # a turn is entered inside its junction
            self._turn_end = junction.s_exit
        self._near = set()
        if to in LANE_CHANGES:
            self.origin = self.lane
            self.lane = self.lane + 1 if to is Motion.LANE_CHANGE_LEFT else \
                self._right_of(self.lane, pull_over)
            self.path = self._plan_into(self.lane, ego)
        elif abort:  # back to the origin; both lanes are in use until the path's end
            self.lane, self.origin = self.origin, self.lane
            self.path = self._plan_into(self.lane, ego)
        else:
            self.origin = self.lane
            self.path = None

    def _plan_into(self, lane: int, ego: EgoState) -> LaneChangePath:
        return start_lane_change(self.road.lane(lane), lane, ego.x, ego.y, ego.heading,
                                 ego.speed, self.params.lane_change)

    def _leads(self, traffic: dict[int, LaneTraffic], s: float, d: float,
               v: float) -> tuple[Neighbour, ...]:
        """On a path: the vehicle ahead in the target lane, and the one ahead in the origin
        lane while the car's body still overlaps that lane; on a pass, only from the moment
        it is near enough to matter (`_still_near`) on (so that braking for it does not make
        it far again and release it: no chatter)."""
        if self.path is None:
            return ()
        leads = [n for n in (traffic[self.lane].ahead,) if n is not None] \
            if self.lane in traffic else []
        origin = self.road.lane(self.origin)
        clear = 0.5 * float(origin.width_at(s)) + 0.5 * self.vehicle.width + self.params.mirrors
        left_behind = traffic[self.origin].ahead if self.origin in traffic else None
        if left_behind is not None and abs(d - float(origin.offset_at(s))) < clear and (
                not self._passing or left_behind.track_id in self._near
                or self._still_near(left_behind, v)):
            self._near.add(left_behind.track_id)  # near once: a lead until the body is out
            leads.append(left_behind)
        return tuple(leads)

    def _still_near(self, n: Neighbour, v: float) -> bool:
        """The vehicle ahead in the lane being left still constrains the car's speed: within
        UN R157's d_min at speed `v` [m/s], or closing with under ``pass_ttc`` to collision.
        Farther, the target lane's vehicle is the lead: a pass does not trail the car it
        passes."""
        closing = v - n.speed
        return n.gap < r157_min_gap(v) or (closing > 0.0 and
                                           n.gap < self.params.pass_ttc * closing)


def _turn(junction: Junction | None) -> Turn | None:
    """The route's command at `junction` (None: no junction)."""
    return None if junction is None else Turn(junction.manoeuvre.value)
