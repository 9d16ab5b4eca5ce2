"""The motion FSM in the planner: lane occupancy in, the lane to keep and the path out.

Positions are stations s [m] along the route's reference line and lateral offsets d [m]
from it (left +); lanes are ego-direction lane indices (0 rightmost, `SHOULDER` the paved
shoulder). Per tick:

1. the tracks are placed in the lane kept, the origin lane and the neighbours that go on
   for a whole change (`planner.lane_occupancy`), and the shoulder when a flat tyre pulls
   the car over from lane 0;
2. the inputs of the motion FSM (`planner.fsm.motion`): the lane kept is *blocked* once a
   slower vehicle has blocked it for ``blocked_time``; the lanes left and right are free or
   not (by the tracks, rear traffic included: `planner.lane_occupancy.is_free`, UN R157's
   rule that a vehicle approaching from behind need not brake harder than 3 m/s^2, judged at
   the lowest speed the car plans during the move, e.g. a flat tyre's slowing; a vehicle
   coming up behind that does not brake is judged over the whole time the car will be in
   the lane, for a pull-over through a driving lane its stay there too (`_pull_over_stay`:
   the wait before the next change and that change toward the shoulder); the tracks
   reach 60 m behind, less past a vehicle alongside in the lane, which hides what follows
   it: the lane is free only ``rear_view_time`` after such a vehicle was last alongside,
   time for the tracks of what it hid to be confirmed); a pass
   would clear the blocking vehicle (below); a pass into a lane would be over, the car
   back in its own lane, before any vehicle coming up behind in that lane, keeping its
   speed, is nearer than UN R157's rear distance (`planner.rear_pass`: the move out timed
   on the path planned, the pass at the speed the car wants, the way back a lane change at
   that speed); the route needs the car to move right when
   the lane kept does not go on to max(``prepare_distance``, ``prepare_time`` v) ahead (a
   lane that ends at an exit or a lane drop is left in time); the route's turn at a
   junction; the lane the driver's turn-signal stalk asks for (one lane at a time towards
   it); during a change, whether the target lane is still free, whether the car's
   centre is inside it (committed) and whether the path is done;
3. the motion FSM steps once.

Entering a lane change makes the target lane the lane kept (its speed plan and, once done,
its camera lane) and plans the Hermite path into it from the car's pose
(`planner.lane_change_path`); the change is done when the car's station reaches the path's
end. An abort plans the same kind of path back to the origin lane, followed in LANE_KEEP
until its end, with its own parameters (``abort_change``): the car still heads out of the
lane, and a cubic from that heading runs on outwards for about a quarter of its length
before it turns back (4/27 of the length times the heading's slope), so the way back is
the shortest whose peak lateral acceleration is within 2 m/s^2 rather than the 0.85 m/s^2
of a planned change. At 50 km/h, 0.3 m out and heading out at 1.25 m/s, the longer path
ran on 1.09 m further out (its body 0.5 m over the line it had not reached), this one
0.46 m (braking 1.25 m/s across at 2 m/s^2 takes 0.39 m).

While a path is followed, the vehicle ahead in the lane kept (the target lane) is the ACC's
lead; the vehicle ahead in the origin lane is a lead too while the car's body (mirrors
included) still overlaps that lane (`leads`): the car does not run into the vehicle it is
leaving. On a pass (a change taken to pass a slower vehicle), the vehicle
passed counts only once the path does not clear it by ``pass_margin_keep`` (`clears`,
below; a hysteresis below the margin a pass starts with): the car does not
trail it through the pass, yet stops behind it rather than run into it if
it does not get past. A change the route or a flat tyre asks for keeps trailing it (the car
may be moving into that vehicle's path).

A pass starts only if its path *clears* the vehicle ahead: at the station where the car's
front bumper reaches that vehicle's rear (it at its speed, the car at the higher of its speed
and the speed it wants), the path's centre is at least half the car's width + half the
vehicle's width (across the road, from its track) + ``pass_margin`` from the vehicle's
centre. (The front corners are then farther out still: the car heads away from it.) From a
standstill the path is ``min_length`` long (`planner.lane_change_path`), which clears a car
only from about 9 m behind; so with overtaking on, behind a (nearly) stationary vehicle that
blocks the lane the car stops ``pass_gap`` back instead of at the ACC's standstill gap d0: the
manoeuvre asks the ACC to keep ``room`` = ``pass_gap`` - d0 more (the room to pull out, as a
driver leaves to see the tyres of the car ahead), as much of it as a stop at
``room_decel`` still leaves, or, when the stop at d0 alone needs more (a vehicle revealed
late by a cut-out), a stop at ``room_decel_hard``; the room granted stays granted while the
car stops behind that vehicle (`_room`). Without overtaking, the ACC's d0 holds (UN R157
4.2.1: 2 to 6 m). From 2 to 6 m behind a car of the same width no forward path clears it
(the turning circle): a pass from there waits for good.

Keeping right after a pass waits for a car behind in the right lane to be
``keep_right_gap`` back (a margin over the gap that aborts): that many seconds at the car's
speed, or, while a faster vehicle comes up behind in the lane kept (it would reach the car
within ``yield_time``: the FSM's ``yield_behind``, no ``keep_time`` then), at that car's own
speed (UN R157's t_G is the time the vehicle behind takes to cover the gap): a vehicle just
passed that stands or is slow does not hold the car in the faster vehicle's way.

On a road where the leftmost lane of the car's direction has an oncoming lane beside it
(and no lane to its left), a blocked car passes through the oncoming lane (-1) when
`planner.oncoming_pass` finds the pass safe (no vehicle alongside in that lane, none coming
up behind in it the car's way) and the path clears the vehicle; otherwise the reason is
logged once per change of reason, its figures aside (a motion change lane_keep ->
lane_keep). The change into lane -1 is committed once the car is alongside the vehicle
passed (it is no longer ahead in the car's own lane); before that a tracked oncoming
vehicle that makes the rest of the pass unsafe aborts it. In lane -1 the car goes back as
soon as the vehicle passed is behind by max(its speed x ``t_return``, ``return_gap``, the
car's speed x the rear rule's t_G) + ``back_margin`` and the own lane is free; its speed
there (and on the ways in and back) is capped by `planner.oncoming_pass.speed_cap`.

At a town junction where the route turns, the turn is entered when the car's centre passes
the stop line and done at the junction's exit (`RoadMap.junctions`); its path is the map's
lane 0, which turns along the junction's arc (`world.map.town`), so the path needs nothing
planned here. Lane 0 is the only lane through a turn: the route lane change brings the car
into it before the junction ("a lane ends ahead").
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from perception.messages import EgoState, Track
from planner.fsm.acc import AccParams
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
from planner.lane_change_path import (
    LaneChangeParams,
    LaneChangePath,
    RoutePose,
    path_length,
    plan_duration,
    route_pose,
    start_lane_change_at,
)
from planner.lane_occupancy import (
    LaneTraffic,
    Neighbour,
    OccupancyParams,
    is_blocked,
    is_free,
    lane_traffic,
    rear_decel_needed,
)
from planner.oncoming_pass import (
    Oncoming,
    PassParams,
    Slow,
    Verdict,
    decide,
    plan_pass,
    speed_cap,
    tracks_reason,
)
from planner.oncoming_pass import closing_time as time_to_cover
from planner.rear_pass import Pass, RearPassParams, rear_catches
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
    pass_margin: float = 0.4  # [m] a pass starts on a path that clears a vehicle by this,
    #   side to side ...
    pass_margin_keep: float = 0.2  # [m] ... and once under way, the vehicle passed is in
    #   the way (a lead) only when the path clears it by less than this (hysteresis: the
    #   track's box and gap wobble by tenths of a metre as the car moves past it)
    pass_gap: float = 12.0  # [m] with overtaking on, the gap kept behind a stationary vehicle
    #   that blocks the lane: room for a pass path from a standstill to clear it (by ~0.9 m)
    rear_view_time: float = 0.5  # [s] after a vehicle alongside in a lane (which hides the
    #   lane behind it), its rear counts as seen again only after this: the tracks of what
    #   it hid need 3 of 5 scans at 10 Hz to be confirmed (`perception.tracking`)
    room_decel: float = 2.5  # [m/s^2] the room is kept only as far as a stop at this
    #   leaves it (below ISO 15622's 3.5 m/s^2: never a hard stop for it) ...
    room_decel_hard: float = 6.5  # [m/s^2] ... unless the stop at d0 alone already
    #   needs more (a vehicle revealed late: the stop is a hard one anyway); then as far as a
    #   stop at this leaves it (under the emergency stop's A_EMERGENCY, which a late stop at
    #   d0 ends in): a car stopped at d0 behind a vehicle of its width has no forward path
    #   around it, and would wait behind it for good. 50 km/h, 27 m from a stopped car:
    #   8 m of room (A_HARD's 5 m/s^2 would leave 4.1, a stop short of the 9 m a pass
    #   path from a standstill needs)
    stationary: float = 0.5  # [m/s] a vehicle slower than this is stationary
    same_place: float = 4.0  # [m] a stationary vehicle's new track whose rear is within this
    #   of the one granted room is that vehicle (`_room`): two standing vehicles' rears are a
    #   vehicle's length and a gap apart, and the first tracks of a car 50 m ahead placed its
    #   rear 2 to 3.6 m short of where the tracks placed it from near
    keep_right_gap: float = 2.0  # [s] keeping right waits for this time gap to a car behind
    #   in the right lane (UN R157's t_G of 1 s aborts a change: the margin between the two
    #   keeps a gap that hovers near t_G from starting and aborting changes)
    yield_time: float = 10.0  # [s] a vehicle behind in the lane kept that would reach the
    #   car within this at the speeds now comes up behind: keeping right yields to it
    yield_margin: float = 1.0  # [m/s] ... when it is faster than the car by more than this
    back_margin: float = 2.0  # [m] the return from the oncoming lane waits for this more
    #   gap to the vehicle passed than the rear rule's (a standing vehicle's is
    #   gap >= v t_G, no hysteresis in decelerations: its track's box wobbles by tenths of
    #   a metre, which would start and abort the return)
    motion: MotionParams = field(default_factory=MotionParams)
    occupancy: OccupancyParams = field(default_factory=OccupancyParams)
    lane_change: LaneChangeParams = field(default_factory=LaneChangeParams)
    abort_change: LaneChangeParams = field(default_factory=lambda: LaneChangeParams(
        a_lat_design=2.0, t_min=1.5, t_max=3.0, t_cap=8.0, min_length=10.0))  # the way back
    #   of an abort (module doc): the shortest path whose peak lateral acceleration is within
    #   2 m/s^2 (ISO 11270's lane keeping bound is 3 m/s^2; the curves' a_lat_max too)
    oncoming_pass: PassParams = field(default_factory=PassParams)  # a pass through the
    #   oncoming lane (`planner.oncoming_pass`)


@dataclass(frozen=True, slots=True)
class Manoeuvre:
    """The motion layer's output for one tick."""

    motion: Motion
    lane: int  # [-] the lane kept, or moved into (ego-direction index, `SHOULDER`)
    origin: int  # [-] the lane left by a lane change in hand (== lane otherwise)
    path: LaneChangePath | None  # the lane-change (or abort) path being followed
    leads: tuple[Neighbour, ...] = ()  # on a path: the vehicles ahead in the lanes occupied
    room: float = 0.0  # [m] more gap for the ACC to keep behind track `room_for` (the room
    #   to pull out around a stationary vehicle it may pass)
    room_for: int | None = None  # the track id of that vehicle
    speed_cap: float = math.inf  # [m/s] the highest speed while the car is in the oncoming
    #   lane (`planner.oncoming_pass.speed_cap`); inf elsewhere


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
        self._v_want = 0.0  # [m/s] the speed the car wants, this tick
        self._hidden_until: dict[int, float] = {}  # [s] lane -> its rear view is whole again
        self._blocked_since: float | None = None
        self._turn_end = math.inf  # [m] where the turn in hand ends (its junction's exit)
        self._near: set[int] = set()  # tracks of the lane being left found in the way
        #   (`_leads`)
        self._pose: RoutePose | None = None  # the car's pose on the route, last projected
        #   (`_route_pose`)
        self._station: float | None = 0.0  # [m] the car's station last tick (first: the route's
        #   start, `Planner.localise`; a town route crossing itself passes a point twice:
        #   `world.hdmap.ReferenceLine.project`)
        self._passing = False  # the change in hand is one to pass a slower vehicle
        self._no_pass = ""  # why the car stays behind a slower vehicle it may not pass
        #   through the oncoming lane (logged once per change of reason)
        self._no_pass_now = ""  # ... this tick's reason
        self._passed: int | None = None  # the track passed through the oncoming lane
        self._alongside = False  # the car has drawn alongside it (the pass is committed)
        self._kept: tuple[int, float, float] | None = None  # the room granted so far
        #   behind a stationary vehicle: (its track id, the room [m], the station [m] of its
        #   rear less the car's front overhang) (`_room`)

    def update(self, ego: EgoState, v_want: float, tracks: Sequence[Track],
               pull_over: bool = False, v_rear: float | None = None,
               lane_request: int | None = None,
               ) -> tuple[Manoeuvre, tuple[StateChange, ...]]:
        """Step with the ego estimate, the speed it wants [m/s], the confirmed tracks,
        whether to pull over onto the shoulder (a flat tyre), the lowest speed [m/s] the
        car plans during a lane change (the rear traffic is judged at it; default: its
        speed now) and the lane the driver's turn-signal stalk asks for (None: at rest)."""
        s, d = (float(a) for a in self.road.local_coordinates((ego.x, ego.y), self._station))
        self._station = s
        # the pose the lane checks use, projected while the map still holds this point's
        # projection (`world.hdmap.ReferenceLine.project` keeps the last points'): the
        # tracks' come next
        self._route_pose(ego)
        lanes = self._lanes_around(s, ego.speed, pull_over)
        traffic = lane_traffic(self.road, tracks, ego.t, s, lanes,
                               self.params.occupancy, self.vehicle)
        for k, lt in traffic.items():
            if lt.alongside:  # it hides the lane behind it from the LiDAR
                self._hidden_until[k] = ego.t + self.params.rear_view_time
        self._v_want = v_want
        v_low = ego.speed if v_rear is None else min(ego.speed, v_rear)
        x = self._input(ego, s, d, v_want, v_low, traffic, pull_over)
        if lane_request is not None and lane_request != self.lane:
            x = replace(x, driver_lane=1 if lane_request > self.lane else -1)
        change = transition(self.machine.state, x, self.params.motion)
        if change is not None:
            self._passing = is_pass(self.machine.state, x, self.params.motion)
            # a lane change given up before it was done: back to the origin lane
            abort = self.machine.state in LANE_CHANGES and not x.change_done
            self._enter(change.to, abort, ego, s, pull_over)
        elif self.path is not None and self.motion is Motion.LANE_KEEP and s >= self.path.end:
            self.path = None  # the way back after an abort is done
            self.origin = self.lane
        changes = self.machine.apply(ego.t, change) + self._why_no_pass(ego, x)
        room_for, room = self._room(traffic, s, ego.speed, v_want)
        cap = speed_cap(float(self.road.speed_limit_at(s)), self.params.oncoming_pass) \
            if _oncoming(self.lane) or _oncoming(self.origin) else math.inf
        return Manoeuvre(self.motion, self.lane, self.origin, self.path,
                         self._leads(traffic, s, d, ego.speed), room, room_for, cap), changes

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
        if self._oncoming_side(s):
            near.add(-1)
        return tuple(sorted(near))

    def _oncoming_side(self, s: float) -> bool:
        """Whether overtaking is on, the car keeps the leftmost lane of its direction at
        station `s` [m] and an oncoming lane lies beside it: the only way past is that lane."""
        section = self.road.cross_section_at(s)
        return (self.params.overtake and self.lane == section.lanes - 1
                and section.oncoming_lanes > 0)

    def _why_no_pass(self, ego: EgoState, x: MotionInput) -> tuple[StateChange, ...]:
        """While the car keeps its lane behind a slower vehicle that blocks it on a road
        whose only way past is the oncoming lane, why it may not pass there now (this
        tick's `_oncoming_input`): a change of reason is logged (the motion state stays
        LANE_KEEP), once per change, not every tick."""
        reason = self._no_pass_now if self.motion is Motion.LANE_KEEP and x.blocked else ""
        if _kind(reason) == _kind(self._no_pass):  # the same reason with other figures
            return ()
        self._no_pass = reason
        if not reason:
            return ()
        state = self.motion.value
        return (StateChange(ego.t, "motion", state, state, reason),)

    def _oncoming_input(self, ego: EgoState, s: float, x: MotionInput, blocked_now: bool,
                        v_low: float, traffic: dict[int, LaneTraffic]) -> MotionInput:
        """`x` with the inputs of a pass through the oncoming lane: in it, whether the car
        may take its own lane back; behind a slower vehicle where the oncoming lane is the
        only way past, whether a pass is safe (`planner.oncoming_pass.decide`, the lane free
        alongside and behind) and its path clears the vehicle (else why not)."""
        self._no_pass_now = ""
        if _oncoming(self.lane):
            back = self.road.lanes_at(s) - 1
            return replace(x, left_free=False, right_free=False, in_oncoming=True,
                           back_free=self._can_plan(back, ego)
                           and self._back_free(ego, s, v_low, traffic))
        slow = traffic[self.lane].ahead
        if (not blocked_now or slow is None or self.motion is not Motion.LANE_KEEP
                or not self._oncoming_side(s)):
            return x
        self._passed = slow.track_id
        verdict = self._decide(ego, s, slow, traffic[-1])
        ok = verdict.ok and self._pass_clears(ego, s, -1, traffic)
        self._no_pass_now = verdict.reason or (
            "" if ok else "no pass: too near the vehicle ahead for a path that clears it")
        return replace(x, oncoming_pass=ok)

    def _decide(self, ego: EgoState, s: float, slow: Neighbour,
                oncoming: LaneTraffic) -> Verdict:
        """`planner.oncoming_pass.decide` for passing `slow` from the car's centre station
        `s` [m], with the oncoming lane's traffic (nothing alongside in it, nor coming up
        behind in it in the car's direction faster than the rear rule allows; one behind
        that drives away, the oncoming traffic that has passed, does not count)."""
        if oncoming.alongside:
            return Verdict(False, "no pass: a vehicle alongside in the oncoming lane")
        behind = oncoming.behind
        if behind is not None and behind.speed > 0.0 and rear_decel_needed(
                behind.gap, behind.speed, ego.speed, self.params.occupancy) \
                > self.params.occupancy.rear_decel:
            return Verdict(False, "no pass: a vehicle coming up behind in the oncoming lane")
        ahead = oncoming.ahead
        cars = () if ahead is None else (Oncoming(ahead.gap, -ahead.speed),)
        return decide(self.road, s + self.vehicle.front_overhang, ego.speed, self._v_want,
                      Slow(slow.gap, max(slow.speed, 0.0), slow.length), cars,
                      self.vehicle.length, self.params.oncoming_pass)

    def _still_safe(self, ego: EgoState, traffic: dict[int, LaneTraffic]) -> bool:
        """During a pass through the oncoming lane, until the car is alongside the vehicle
        it passes: whether no tracked oncoming vehicle makes the rest of the pass unsafe
        (`planner.oncoming_pass.tracks_reason`). Once alongside it (the vehicle no longer
        ahead in the car's own lane) the pass is committed: true from then on."""
        own = traffic.get(self.origin if self.origin >= 0 else self.lane + 1)
        slow = None if own is None else own.ahead
        if slow is None or slow.track_id != self._passed:
            self._alongside = True
        if self._alongside or slow is None:
            return True
        onc = traffic[-1]
        plan = plan_pass(ego.speed, self._v_want, Slow(slow.gap, max(slow.speed, 0.0),
                                                        slow.length),
                         self.vehicle.length, self.params.oncoming_pass)
        cars = () if onc.ahead is None else (Oncoming(onc.ahead.gap, -onc.ahead.speed),)
        return not onc.alongside and (plan is None or not tracks_reason(
            plan, self._v_want, cars, self.params.oncoming_pass))

    def _back_free(self, ego: EgoState, s: float, v_low: float,
                   traffic: dict[int, LaneTraffic]) -> bool:
        """In the oncoming lane: whether the car may take its own lane back now: the pass
        became unsafe before it drew alongside (`_still_safe`), or its own lane is free
        (`planner.lane_occupancy.is_free`) with the vehicle passed behind by its speed times
        ``t_return``, ``return_gap`` at least (`planner.oncoming_pass`), and at least the
        car's speed times the rear rule's t_G, plus ``back_margin``."""
        if not self._still_safe(ego, traffic):
            return True
        if not self._alongside:
            return False
        own = traffic.get(self.road.lanes_at(s) - 1)
        if own is None or not is_free(own, ego.speed, self.params.occupancy, v_low):
            return False
        p, occ = self.params.oncoming_pass, self.params.occupancy
        return own.behind is None or own.behind.gap >= max(
            max(own.behind.speed, 0.0) * p.t_return, p.return_gap,
            ego.speed * occ.rear_time_gap) + self.params.back_margin

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

    def _input(self, ego: EgoState, s: float, d: float, v_want: float, v_low: float,
               traffic: dict[int, LaneTraffic], pull_over: bool) -> MotionInput:
        p, v, t = self.params, ego.speed, ego.t
        blocked_now = is_blocked(traffic[self.lane], v, v_want, p.occupancy, self.acc)
        if not blocked_now:
            self._blocked_since = None
        elif self._blocked_since is None:
            self._blocked_since = t
        blocked = self._blocked_since is not None and t - self._blocked_since >= p.blocked_time
        yielding = self._yields(traffic[self.lane], v)
        left = traffic.get(self.lane + 1) if self.lane != SHOULDER else None
        right_of = self._right_of(self.lane, pull_over)
        right = traffic.get(right_of) if self.lane != SHOULDER and (
            right_of >= 0 or right_of == SHOULDER) else None  # never the oncoming lane
        x = MotionInput(
            t=t, since=self.machine.since, overtake=p.overtake, blocked=blocked,
            left_free=left is not None and self._seen(left, t)
            and self._can_plan(left.lane, ego) and self._free_to_start(left, ego, s, v_low,
                                                                       traffic),
            right_free=right is not None and self._seen(right, t)
            and self._can_plan(right.lane, ego)
            and self._free_to_start(right, ego, s, v_low, traffic,
                                    self._pull_over_stay(right.lane, s, v_low, pull_over)),
            clears_left=not blocked_now or left is None
            or self._pass_clears(ego, s, self.lane + 1, traffic),
            clears_right=not blocked_now or right is None or right.lane == SHOULDER
            or self._pass_clears(ego, s, self.lane - 1, traffic),
            outruns_left=not blocked_now or left is None
            or self._outruns(ego, s, left, traffic),
            outruns_right=not blocked_now or right is None or right.lane == SHOULDER
            or self._outruns(ego, s, right, traffic),
            right_clear=right is not None and right.lane != SHOULDER
            and not is_blocked(right, v, v_want, p.occupancy, self.acc)
            and self._clear_behind(right, v, yielding),
            yield_behind=yielding,
            route_lane=min(self._lanes_ahead(s, v) - 1 - self.lane, 0),
            pull_over=pull_over and self.lane != SHOULDER,
            turn=_turn(self._junction_at(s)),
            turn_done=self.motion in TURNS and s >= self._turn_end,
        )
        x = self._oncoming_input(ego, s, x, blocked_now, v_low, traffic)
        if self.motion not in LANE_CHANGES or self.path is None:
            return x
        if _oncoming(self.lane):  # into the oncoming lane: committed once alongside (module doc)
            safe = self._still_safe(ego, traffic) or not self._can_plan(self.origin, ego)
            return replace(x, target_free=safe, committed=self._alongside,
                           change_done=s >= self.path.end)
        target = self.road.lane(self.lane)
        centre, width = float(target.offset_at(s)), float(target.width_at(s))
        # an abort plans a path back: a car that heads off the origin lane goes on instead
        v_end, t_move = self._rear_move(self.path, traffic, s, v, v_low, p.pass_margin_keep)
        t_move += self._pull_over_stay(self.lane, s, v_end, pull_over)
        target_free = is_free(traffic[self.lane], v, p.occupancy, v_end, under_way=True,
                              t_move=t_move) or not self._can_plan(self.origin, ego)
        return replace(x, target_free=target_free,
                       committed=abs(d - centre) < 0.5 * width, change_done=s >= self.path.end)

    def _yields(self, kept: LaneTraffic, v: float) -> bool:
        """Whether a vehicle behind in the lane kept (`kept`) comes up on the car at speed
        `v` [m/s]: faster by more than ``yield_margin``, it would reach it within
        ``yield_time`` (module doc)."""
        p, behind = self.params, kept.behind
        if behind is None or behind.speed <= v + p.yield_margin:
            return False
        return behind.gap < (behind.speed - v) * p.yield_time

    def _clear_behind(self, right: LaneTraffic, v: float, yielding: bool) -> bool:
        """Whether the vehicle behind in the lane to the right, if any, is
        ``keep_right_gap`` back: seconds at the car's speed `v` [m/s], or at its own while
        the car yields to a faster vehicle behind it (`yielding`, module doc)."""
        if right.behind is None:
            return True
        speed = max(right.behind.speed, 0.0) if yielding else v
        return right.behind.gap >= speed * self.params.keep_right_gap

    def _free_to_start(self, lt: LaneTraffic, ego: EgoState, s: float, v_low: float,
                       traffic: dict[int, LaneTraffic], stay: float = 0.0) -> bool:
        """Whether a move into `lt`'s lane may start now (`planner.lane_occupancy.is_free`):
        the rear rules judged at the speed the car will have on the path into it and over
        the time that path takes (`_rear_move`) plus `stay` [s], the time the car stays in
        the lane after it (`_pull_over_stay`)."""
        behind = lt.behind
        if behind is None or behind.speed <= v_low or lt.lane == SHOULDER:
            return is_free(lt, ego.speed, self.params.occupancy, v_low)
        v_end, t_move = self._rear_move(self._plan_into(lt.lane, ego), traffic, s, ego.speed,
                                        v_low, self.params.pass_margin)
        return is_free(lt, ego.speed, self.params.occupancy, v_end, t_move=t_move + stay)

    def _pull_over_stay(self, lane: int, s: float, v: float, pull_over: bool) -> float:
        """[s] how long a car pulling over (`pull_over`) stays in driving lane `lane` once
        it is in it, at speed `v` [m/s]: ``route_keep_time``, then the whole change on
        toward the shoulder (its body is in the lane until near that path's end), a lane
        change at `v` (``t_cap`` at a standstill); 0 on the shoulder or when not pulling
        over. A vehicle coming up behind in the lane that does not brake for the car must
        stay clear of it all that time: a flat tyre's crawl cannot get away from it."""
        if not pull_over or lane == SHOULDER:
            return 0.0
        lc = self.params.lane_change
        width = float(self.road.lane(lane).width_at(s))
        change = path_length(v, plan_duration(width, 0.0, v, lc), lc) / v if v > 0.0 \
            else lc.t_cap
        return self.params.motion.route_keep_time + change

    def _rear_move(self, path: LaneChangePath, traffic: dict[int, LaneTraffic], s: float,
                   v: float, v_low: float, margin: float) -> tuple[float, float]:
        """The speed [m/s] the car will have on `path` from station `s` [m] at speed `v`
        [m/s], and the time [s] it takes to the path's end: `v_low` [m/s], or the speed of
        the vehicle ahead in the lane left when the path does not clear it by `margin` [m]
        (`clears`: the car trails it); the time is the path's length left at that speed, at
        most ``t_cap`` (a car at a standstill: ``t_cap``). A change under way is judged to
        its end, not to its commit point: a car closing fast seen just after the start
        reaches the ego after the commit point, while it still moves over, slow."""
        ahead = traffic[self.origin].ahead if self.origin in traffic else None
        v_end = v_low
        if ahead is not None and ahead.speed < v_end and not self.clears(path, ahead, s, v,
                                                                         margin):
            v_end = max(ahead.speed, 0.0)
        t_cap = self.params.lane_change.t_cap
        left = max(path.end - s, 0.0)
        return v_end, min(left / v_end, t_cap) if v_end > 0.0 else (t_cap if left else 0.0)

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
            self.lane = self._target(to, s, pull_over)
            self._alongside = False
            self.path = self._plan_into(self.lane, ego)
        elif abort:  # back to the origin; both lanes are in use until the path's end
            self.lane, self.origin = self.origin, self.lane
            self.path = self._plan_into(self.lane, ego, self.params.abort_change)
        else:
            self.origin = self.lane
            self.path = None

    def _target(self, to: Motion, s: float, pull_over: bool) -> int:
        """The lane a change to `to` goes into at station `s` [m]: left of the leftmost lane
        of the car's direction, the oncoming lane -1; right of the oncoming lane, that
        leftmost lane; else the next lane (right of lane 0: the shoulder when pulling over)."""
        n = self.road.lanes_at(s)
        if to is Motion.LANE_CHANGE_LEFT:
            return self.lane + 1 if self.lane + 1 < n else -1
        return n - 1 if _oncoming(self.lane) else self._right_of(self.lane, pull_over)

    def _plan_into(self, lane: int, ego: EgoState,
                   params: LaneChangeParams | None = None) -> LaneChangePath:
        """The path into `lane` from the car's pose (``lane_change``, or `params`: an
        abort's ``abort_change``)."""
        # the estimate of a standing car's speed may be a hair below 0; the car's station
        # this tick is the projection's hint (a bend that turns back on itself passes near
        # the car twice)
        return start_lane_change_at(self.road.lane(lane), lane, self._route_pose(ego),
                                    max(ego.speed, 0.0),
                                    self.params.lane_change if params is None else params)

    def _can_plan(self, lane: int, ego: EgoState) -> bool:
        """Whether a path into `lane` starts from the car's pose (it heads less than 90
        degrees off the lane, `planner.lane_change_path.can_start`): a car that does not
        (spun round) holds its lane, and a stop for a flat tyre is made in it. Every lane
        shares the route's tangent, so the answer is the same for each (`RoutePose`)."""
        self.road.lane(lane)  # an IndexError for a lane the road does not have
        return self._route_pose(ego).can_start

    def _route_pose(self, ego: EgoState) -> RoutePose:
        """The car's pose on the route (`planner.lane_change_path.route_pose`), its station
        this tick the hint: projected once per pose and hint, for every lane it may plan
        into or check."""
        pose = self._pose
        if pose is None or not pose.is_for(ego.x, ego.y, ego.heading, self._station):
            pose = self._pose = route_pose(self.road, ego.x, ego.y, ego.heading, self._station)
        return pose

    def _leads(self, traffic: dict[int, LaneTraffic], s: float, d: float,
               v: float) -> tuple[Neighbour, ...]:
        """On a path: the vehicle ahead in the target lane, and the one ahead in the origin
        lane while the car's body still overlaps that lane; on a pass, only from the moment
        the path does not clear it by ``pass_margin_keep`` (`clears`) on (so that braking for
        it does not release it: no chatter)."""
        if self.path is None:
            return ()
        leads = [n for n in (traffic[self.lane].ahead,) if n is not None] \
            if self.lane in traffic else []
        p = self.params
        origin = self.road.lane(self.origin)
        clear = 0.5 * float(origin.width_at(s)) + 0.5 * self.vehicle.width + p.mirrors
        left_behind = traffic[self.origin].ahead if self.origin in traffic else None
        if left_behind is not None and abs(d - float(origin.offset_at(s))) < clear and (
                not self._passing or left_behind.track_id in self._near
                or not self.clears(self.path, left_behind, s, v, p.pass_margin_keep)):
            self._near.add(left_behind.track_id)  # near once: a lead until the body is out
            leads.append(left_behind)
        return tuple(leads)

    def clears(self, path: LaneChangePath, n: Neighbour, s: float, v: float,
               margin: float | None = None) -> bool:
        """Whether the car, on `path` from its centre's station `s` [m] at speed `v` [m/s],
        clears vehicle `n` ahead in the lane it leaves: at the station where its front bumper
        reaches n's rear (n at its speed, the car at max(v, the speed it wants)), the path's
        centre is half the car's width + n's half width + `margin` (``pass_margin``) [m]
        from n's centre (module doc)."""
        v_car = max(v, self._v_want)
        if v_car <= n.speed:
            return True  # it never reaches it
        meet = s + n.gap * v_car / (v_car - n.speed)
        target = self.road.lane(path.target_index)
        y = float(target.offset_at(meet)) + float(path.offset_at(meet))
        need = 0.5 * self.vehicle.width + n.half_width + (
            self.params.pass_margin if margin is None else margin)
        return abs(y - n.offset) >= need

    def _outruns(self, ego: EgoState, s: float, lt: LaneTraffic,
                 traffic: dict[int, LaneTraffic]) -> bool:
        """Whether a pass of the vehicle ahead into `lt`'s lane started now would be over,
        the car back in its lane, with every vehicle coming up behind in `lt`, at its speed,
        still UN R157's rear distance back (`planner.rear_pass.rear_catches`): the move out
        timed on the path planned into that lane, the pass at the speed the car wants, the
        move back a lane change at that speed."""
        slow = traffic[self.lane].ahead
        if slow is None or not lt.following or not self._can_plan(lt.lane, ego):
            return True
        p, v, v_pass = self.params, max(ego.speed, 0.0), self._v_want
        rp = RearPassParams(p.oncoming_pass.a_pass, p.keep_right_gap)
        out = max(self._plan_into(lt.lane, ego).end - s, 0.0)
        t_out = time_to_cover(out, v, v_pass, rp.a_pass) if v_pass > 0.0 else 0.0
        width = float(self.road.lane(self.lane).width_at(s))
        t_back = path_length(v_pass, plan_duration(width, 0.0, v_pass, p.lane_change),
                             p.lane_change) / v_pass if v_pass > 0.0 else 0.0
        ps = Pass(v, v_pass, slow, self.vehicle.length, t_out, t_back)
        return rear_catches(ps, lt.following, p.occupancy, rp) is None

    def _seen(self, lt: LaneTraffic, t: float) -> bool:
        """Whether the lane's rear has been in the LiDAR's view for ``rear_view_time`` since
        a vehicle alongside in it last hid what comes behind it."""
        return t >= self._hidden_until.get(lt.lane, -math.inf)

    def _pass_clears(self, ego: EgoState, s: float, lane: int,
                     traffic: dict[int, LaneTraffic]) -> bool:
        """Whether a pass into `lane` started now would clear the vehicle ahead (`clears`)."""
        ahead = traffic[self.lane].ahead
        if ahead is None or not -self.road.cross_section_at(s).oncoming_lanes <= lane \
                < self.road.lanes_at(s):
            return True
        if not self._can_plan(lane, ego):
            return False
        return self.clears(self._plan_into(lane, ego), ahead, s, ego.speed)

    def _room(self, traffic: dict[int, LaneTraffic], s: float, v: float,
              v_want: float) -> tuple[int | None, float]:
        """The track id of a stationary vehicle blocking the lane kept, which the car may
        pass (overtaking on, keeping its lane, a lane beside it), and the room [m] the ACC
        is to keep behind it beyond d0: ``pass_gap`` - d0, or as much of it as a stop from
        speed `v` [m/s] at ``room_decel`` still leaves (never a hard stop for it), or at
        ``room_decel_hard`` when the stop at d0 alone needs more than ``room_decel``
        (`room_left`). The room granted is kept (the largest so far for that vehicle): a
        stop gentler than the deceleration it was granted at would shrink what is left of
        it tick by tick, down to d0, where no path gets around the vehicle. A vehicle is the
        one granted the room when it has the same track id or its rear stands within
        ``same_place`` of that one's: the tracker may give a standing car a new track (it
        lost it, or split its returns) as the car brakes, which must not take the room
        granted back. It is forgotten once the car leaves LANE_KEEP."""
        p = self.params
        ahead = traffic[self.lane].ahead if self.lane in traffic else None
        side = self.lane >= 0 and (
            any(k in traffic for k in (self.lane - 1, self.lane + 1) if k >= 0)
            or self._oncoming_side(s))
        if not p.overtake or not side or self.motion is not Motion.LANE_KEEP:
            self._kept = None
            return None, 0.0
        if (ahead is None or ahead.speed >= p.stationary
                or not is_blocked(traffic[self.lane], v, v_want, p.occupancy, self.acc)):
            return None, 0.0  # the room granted is remembered: a new track's first speeds
            #   wobble above `stationary`
        room = room_left(ahead.gap, v, self.acc.d0, p)
        rear = s + ahead.gap  # [m] its rear's station, less the car's front overhang
        kept = self._kept
        if kept is not None and (kept[0] == ahead.track_id
                                 or abs(kept[2] - rear) <= p.same_place):
            room = max(room, kept[1])
        self._kept = (ahead.track_id, room, rear)
        return ahead.track_id, room


def room_left(gap: float, v: float, d0: float, p: MotionLayerParams) -> float:
    """[m] the room beyond the standstill gap `d0` [m] that a stop from speed `v` [m/s] at
    `gap` [m] behind a stationary vehicle leaves, up to ``pass_gap`` - d0: at ``room_decel``,
    or at ``room_decel_hard`` when a stop at d0 itself needs more than ``room_decel``
    (0 when even that stop cannot leave any)."""
    room = gap - d0
    hard = room <= 0.0 or v * v / (2.0 * room) > p.room_decel
    decel = p.room_decel_hard if hard else p.room_decel
    return min(max(p.pass_gap - d0, 0.0), max(room - v * v / (2.0 * decel), 0.0))


def _oncoming(lane: int) -> bool:
    """Whether lane index `lane` is an oncoming lane (-1, -2, ...: `world.hdmap`), not the
    paved shoulder (`SHOULDER`, also negative) nor a lane of the car's direction."""
    return SHOULDER < lane < 0


def _kind(reason: str) -> str:
    """A reason without its figures (an oncoming car's gap changes every tick; the reason
    does not)."""
    return _FIGURES.sub("#", reason)


_FIGURES = re.compile(r"[0-9]+(\.[0-9]+)?")


def _turn(junction: Junction | None) -> Turn | None:
    """The route's command at `junction` (None: no junction)."""
    return None if junction is None else Turn(junction.manoeuvre.value)
