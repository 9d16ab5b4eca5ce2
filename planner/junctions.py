"""Town junctions for the ACC layer: traffic lights seen by the camera, and giving way.

The HD map lists the route's junctions (`RoadMap.junctions`: stop line, where the turn
starts and ends, the manoeuvre, the control) and the route's traffic lights (their stop
lines and where their heads stand). Positions are stations [m] along the route (the car's
front bumper f, a stop line L); tracks and the junction box are in the map frame. Each tick
(`JunctionMonitor.update`, parameters `JunctionParams`):

**Traffic lights** (event ``red_light``): the next light whose stop line L the front has not
crossed, once within ``approach(v)`` (as `planner.events`). Its colour is the camera's
(`see_lights`, `perception.lights`) if seen within ``light_memory``; red and yellow count
from one frame, green (which lets the car go) from two in a row within
``green_frames_gap``. The car stops, by the ACC's stop law at ``L - f - stop_margin``:

- for red, unless it decided to go on this light's yellow;
- for yellow, if it can still stop before the line at ``yellow_decel``
  (v^2 <= 2 yellow_decel (L - f - stop_margin)), checked each tick; once it cannot, it goes
  on and keeps to that until the light is seen green (it is then near enough to clear the
  line within the yellow phase);
- for an unread light (not seen, or not lately), from the distance it needs to stop at
  ``yellow_decel`` plus ``unseen_margin``: a light the camera cannot read is not driven
  through, and one it reads in time costs nothing. Not at ``a_comf``: the camera reads a
  light only from a fixed distance before its stop line (`perception.lights`), and at town
  speeds the braking distance at ``a_comf`` reaches beyond it: the car would brake for
  lights it has not yet had the chance to read.

Once stopping for a light, the car stops until the camera sees it green (or it decides to
go on its yellow): a missed frame or the colour's memory running out does not let it go.

**Giving way** (event ``give_way``, a stop at the junction's stop line L). The car waits at
the line:

- before a left turn or a U-turn, at a junction of any control: for an oncoming vehicle
  track (on the far arm, in the lanes heading towards the car, up to ``oncoming_reach``
  beyond the box) that will reach the box within ``gap_time`` at its speed towards it, or
  is within ``near_box`` of it whatever its speed (e.g. at its own stop line, about to go
  when the light turns green, as the car's does); at a stop-sign junction, only for one
  that can no longer stop at its own line (moving towards the box with
  v^2 > 2 commit_decel d, d from its front bumper, its centre less half its length, to
  the line): one standing at its line, or still able to stop there, must stop and take its
  turn in the order of arrival (below), which decides between it and the car (waiting for
  it as for a gap, the car would wait for a car that itself waits for the car, first to
  stop); or for any vehicle track in the box
  (inside it, or past its own stop line and moving towards the centre: on its way in)
  that is not moving the car's way;
- at a stop-sign junction, also going straight or turning right: for a vehicle track in
  the box (the same) that is not moving the car's way: a car that took its turn and moved
  off its line is waited for until it has crossed (going as soon as the car first to stop
  has left its line meets it in the box);
- at a stop-sign junction (an all-way stop), in order of arrival (`ArrivalOrder`): first to
  stop, first to go; ties to the right. The car *arrives* when it stands (below
  ``stopped``) with its front 0 to ``arrival_zone`` before its line and no vehicle right in
  front of it (`planner.queue`: queued behind the car at the line, it has not arrived,
  whatever its own estimate of the distance to the line says). A vehicle track
  *waits at a line* of the junction when it stands (below ``moving``) in the inbound lane
  of an arm (right of the arm's axis, within the street's half width), its centre
  ``line_zone_near`` to ``line_zone_far`` beyond the line's distance from the centre (the
  other approaches' lines are as far out as the car's own: the town is symmetric): the
  first car of its queue, not one queued behind it. It arrived when first seen waiting
  there; one first seen already waiting counts as there before the car. The car waits
  for every vehicle that arrived before it (by more than ``tie``), or within ``tie`` of
  it and on its right (coming from the right: travelling 90 deg left of the car's
  heading), until that vehicle no longer waits at its line. It never waits for a vehicle
  that arrived after it, nor for one queued behind another.

**Crossing paths** (also ``give_way``), at a junction of any control and for any
manoeuvre, even with the right of way: a moving vehicle track in or near the box whose
constant-velocity prediction crosses the car's path ahead in time for the car to meet it
(`planner.crossing`, ``crossing``) keeps the car at its line when it can still stop there
at ``commit_decel``, else stops it short of the conflict point (as hard as the stop law
must); already in the box, too. It holds while the prediction crosses, without the gap
hysteresis below.

Like the yellow rule, the decision to give way is taken only while the car can still stop
before the line at ``commit_decel`` (at an all-way stop, where it stops at the line
anyway, not before it has arrived there): once it is moving (faster than ``moving``) and cannot
(v^2 > 2 commit_decel (L - f - stop_margin)) without already waiting, or once its front is
over the line, it is committed to the junction and goes on (the control FSM's emergency
stop still covers a vehicle in its path). A gap that closes after that point is not chased
with a stop the car cannot make.

**Taking a gap** (hysteresis, then commitment: without them a gap is taken and given up
0.1 s later, for an oncoming car the one just gone by had hidden). Once giving way, the car gives
way until it has had nothing to wait for during ``gap_confirm`` in a row: a vehicle that
comes out from behind another, or into the LiDAR's reach, is a confirmed track only after
the tracker's M-of-N confirmation (up to 5 scans at 10 Hz), so a gap is taken once what it
may hide has had the time to show. Then the gap is taken: the car goes, and if its front is
within ``arrival_zone`` of its line, not in a queue, it is committed to the junction (as
above), the way
production stacks commit to a gap (queued farther back, behind a car that goes first, it
is not: the gap is judged again on its way up to the line, as it would take seconds more
to get there: a gap taken 15 m back is turned into seconds later, when the oncoming car
may be there): it gives way there
again only for a safety reason, a vehicle inside the box that is not moving its way (at a
junction whose rules look at the box) while it can still stop before the line at
``commit_decel``; never because an oncoming vehicle closes the gap. So the give-way event
holds at least ``gap_confirm`` each time, and is not taken up again for the gap it left.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from perception.messages import LightDetection, ObjectClass, Track
from planner.crossing import CrossingParams, TurnRates, crossing_stop
from planner.fsm.acc import NO_EVENTS, AccEvent
from planner.limits import A_COMF, A_FIRM
from planner.queue import queued
from world.frames import VehicleInfo
from world.hdmap import (
    Control,
    Junction,
    LightColour,
    Manoeuvre,
    RoadMap,
)


@dataclass(frozen=True, slots=True)
class JunctionParams:
    a_comf: float = A_COMF  # [m/s^2] approach braking
    approach_extra: float = 30.0  # [m] added to the braking distance: room to settle
    stop_margin: float = 0.5  # [m] stop this much (+ the law's margin) before a line
    light_memory: float = 1.0  # [s] a light's colour is trusted this long after it was seen
    green_frames_gap: float = 0.25  # [s] two green frames this close confirm green
    yellow_decel: float = A_FIRM  # [m/s^2] the yellow rule's "can stop" deceleration
    unseen_margin: float = 5.0  # [m] an unread light is stopped for from this + braking
    gap_time: float = 6.0  # [s] an oncoming vehicle nearer than this in time is waited for
    #   (a left turn's critical gap from a standstill, plus margin)
    commit_decel: float = A_FIRM  # [m/s^2] past where it could stop at this, it goes on
    oncoming_reach: float = 100.0  # [m] how far out along the far arm oncoming traffic counts
    moving: float = 0.5  # [m/s] slower than this, a track (or the ego) is not moving
    near_box: float = 12.0  # [m] an oncoming track this near the box counts, moving or not
    same_way: float = 0.7  # [-] cos of the angle within which a track moves the car's way
    stopped: float = 0.1  # [m/s] the car stands below this (its arrival at an all-way stop)
    arrival_zone: float = 4.0  # [m] front bumper this near its line: the car has arrived
    line_zone_near: float = -1.0  # [m] a track's centre this far beyond a line (from the
    line_zone_far: float = 8.0  # [m] ... centre outwards) to this far waits at that line
    tie: float = 1.0  # [s] arrivals this close in time are a tie (the right goes first)
    gap_confirm: float = 0.6  # [s] a gap is taken once nothing was waited for this long: the
    #   tracker's confirmation window (5 LiDAR scans at 10 Hz) and one scan more
    crossing: CrossingParams = field(default_factory=CrossingParams)  # vehicles crossing
    #   the car's path at the junction (`planner.crossing`)


@dataclass(frozen=True, slots=True)
class JunctionEvents:
    active: frozenset[AccEvent] = NO_EVENTS  # RED_LIGHT: stopping for a light (red, a
    #   yellow it can stop for, unread); GIVE_WAY: waiting for a gap before turning / entering
    stop_distance: float = math.inf  # [m] front bumper to where the car must stand
    light: LightColour | None = None  # the next light's colour as last seen (None: unread)

    def holds(self, event: AccEvent) -> bool:
        """Whether `event` holds now."""
        return event in self.active


@dataclass(slots=True)
class _Seen:
    colour: LightColour
    t: float  # [s] frame time


class JunctionMonitor:
    """The junction rules of one run (it remembers the lights seen and yellow decisions)."""

    def __init__(self, road: RoadMap, vehicle: VehicleInfo,
                 params: JunctionParams | None = None) -> None:
        self.road, self.vehicle = road, vehicle
        self.params = params if params is not None else JunctionParams()
        self.lights = road.traffic_lights  # a detection's `light` indexes this
        self._seen: dict[int, _Seen] = {}  # the colour believed, per light
        self._last: dict[int, _Seen] = {}  # the last frame's colour, per light
        self._yellow_go: set[int] = set()  # lights whose yellow the car decided to go on
        self._stopping: set[int] = set()  # lights the car stops for until seen green
        self._waiting: set[int] = set()  # junctions (route order) the car gives way at
        self._committed: set[int] = set()  # junctions the car goes on through (a gap taken,
        #   or past where it could stop): given up only for a safety reason (module doc)
        self._clear_since: dict[int, float] = {}  # [s] junctions waited at: nothing to wait
        #   for since then
        self._order = ArrivalOrder(self.params)  # at the all-way stop ahead
        self._order_at: int | None = None  # the junction (route order) `_order` is for
        # [m] each junction's centre to its stop line (the car's approach; every arm's)
        self._line_out = [self._line_distance(j) for j in road.junctions]
        self._turn_rates = TurnRates(self.params.crossing.moving)

    def see_lights(self, detections: Sequence[LightDetection]) -> None:
        """Take the camera's colours: red or yellow at once; green, which lets the car go,
        only when two frames in a row (within ``green_frames_gap``) agree."""
        for d in detections:
            seen = self._seen.get(d.light)
            if seen is not None and d.t < seen.t:
                continue
            last = self._last.get(d.light)
            self._last[d.light] = _Seen(d.colour, d.t)
            confirmed = last is not None and last.colour is d.colour and \
                d.t - last.t <= self.params.green_frames_gap
            if d.colour is not LightColour.GREEN or confirmed:
                self._seen[d.light] = _Seen(d.colour, d.t)

    def update(self, t: float, station: float, v: float, tracks: Sequence[Track] = (),
               lane: tuple[float, float] | None = None) -> JunctionEvents:
        """The junction events at time `t` [s] for the car's centre at `station` [m] with
        speed `v` [m/s]; `tracks` the confirmed tracks (map frame); `lane` the lane kept
        (its centre's offset from the reference line [m], left +, and its width [m]; by
        default lane 0), where a vehicle queues the car short of its line."""
        p = self.params
        front = station + self.vehicle.front_overhang
        approach = v * v / (2.0 * p.a_comf) + p.approach_extra
        light_stop, colour = self._light(t, front, v, approach)
        if lane is None:
            kept = self.road.lanes[0]
            lane = float(kept.offset_at(station)), float(kept.width_at(station))
        offset, width = lane
        way_stop = self._give_way(t, front, v, approach, tracks,
                                  lambda: queued(self.road, station, front, offset, width,
                                                 tracks))
        cross_stop = self._crossing(t, front, v, approach, offset, tracks)
        if cross_stop is not None:
            way_stop = cross_stop if way_stop is None else min(way_stop, cross_stop)
        stops = [d for d in (light_stop, way_stop) if d is not None]
        happening = {AccEvent.RED_LIGHT: light_stop is not None,
                     AccEvent.GIVE_WAY: way_stop is not None}
        return JunctionEvents(
            active=frozenset(e for e, holds in happening.items() if holds),
            stop_distance=min(stops) if stops else math.inf,
            light=colour,
        )

    # -- lights ----------------------------------------------------------------------------

    def _light(self, t: float, front: float, v: float,
               approach: float) -> tuple[float | None, LightColour | None]:
        p = self.params
        i = next((i for i, f in enumerate(self.lights) if f.s > front), None)
        if i is None:
            return None, None
        room = self.lights[i].s - front - p.stop_margin  # [m] to where the car would stand
        if room + p.stop_margin > approach:
            return None, None
        seen = self._seen.get(i)
        colour = seen.colour if seen is not None and t - seen.t <= p.light_memory else None
        if colour is LightColour.GREEN:
            self._yellow_go.discard(i)
            self._stopping.discard(i)
            return None, colour
        if colour is LightColour.YELLOW:
            if i not in self._yellow_go and v * v > 2.0 * p.yellow_decel * max(room, 0.0):
                self._yellow_go.add(i)  # cannot stop comfortably: go on through
                self._stopping.discard(i)
        elif colour is None and room <= v * v / (2.0 * p.yellow_decel) + p.unseen_margin:
            self._stopping.add(i)  # unread this near: stop for it
        if colour is not None and i not in self._yellow_go:
            self._stopping.add(i)  # red, or a yellow it can stop for
        # once stopping for it, on until the camera sees it green (a frame it misses, or
        # the colour's memory running out, does not let the car go)
        return (room if i in self._stopping else None), colour

    # -- giving way ------------------------------------------------------------------------

    def _crossing(self, t: float, front: float, v: float, approach: float, offset: float,
                  tracks: Sequence[Track]) -> float | None:
        """[m] to where the car must stand for a vehicle crossing its path at the junction
        it approaches (within `approach` [m]) or is in (`planner.crossing`), or None."""
        c = self.params.crossing
        xy, vel = _vehicles(tracks)
        vehicles = [tr for tr in tracks if tr.cls in (ObjectClass.CAR, ObjectClass.TRUCK)]
        rate = self._turn_rates.update([tr.t for tr in vehicles], [tr.id for tr in vehicles],
                                       vel)
        j = next((j for j in self.road.junctions if j.s_exit + c.beyond > front), None)
        if j is None or j.s_stop - front > approach:
            return None
        return crossing_stop(self.road, j, front, v, xy, vel, c, offset, rate)

    def _line_distance(self, j: Junction) -> float:
        """[m] from `j`'s centre back to the car's stop line, along its approach."""
        x, y = (float(a) for a in self.road.line.point(np.array(j.s_stop), np.array(0.0)))
        return -((x - j.x) * math.cos(j.heading) + (y - j.y) * math.sin(j.heading))

    def _give_way(self, t: float, front: float, v: float, approach: float,
                  tracks: Sequence[Track], in_queue: Callable[[], bool],
                  ) -> float | None:
        """[m] to where the car must stand to give way at the next junction, or None; the
        car is at its line (arrived at an all-way stop, committed once it takes a gap) only
        not in a queue (`in_queue()`: a vehicle right in front of it, `planner.queue`)."""
        p = self.params
        k = next((k for k, j in enumerate(self.road.junctions) if j.s_stop > front - 0.5), None)
        if k is None:
            return None
        j = self.road.junctions[k]
        if j.s_stop - front > approach:
            return None
        room = j.s_stop - front - p.stop_margin
        can_stop = v * v <= 2.0 * p.commit_decel * max(room, 0.0)
        if k in self._committed:
            if not (can_stop and self._box_taken(k, tracks)):
                return None
            self._committed.discard(k)  # a safety reason: a vehicle in its path in the box
        wait = self._must_wait(k, tracks)
        if j.control is Control.STOP_SIGNS:
            if self._order_at != k:
                self._order, self._order_at = ArrivalOrder(p), k
            standing = v < p.stopped and 0.0 <= j.s_stop - front <= p.arrival_zone and \
                not in_queue()
            wait = self._order.update(t, j, self._line_out[k], standing, tracks) or wait
        stops_first = j.control is Control.STOP_SIGNS and self._order.arrived is None
        if k not in self._waiting and v > p.moving and not stops_first and not can_stop:
            self._committed.add(k)  # past the last point it could stop comfortably: go on
            return None
        at_line = j.s_stop - front <= p.arrival_zone and not in_queue()
        return room if self._gives_way(t, k, wait, at_line) else None

    def _gives_way(self, t: float, k: int, wait: bool, at_line: bool) -> bool:
        """Whether the car gives way at junction `k` at time `t` [s], `wait` whether it must
        now: while it must, and then until it need not for ``gap_confirm``; the gap is then
        taken, and the junction committed if the car is `at_line` (its front within
        ``arrival_zone`` of its stop line); queued farther back, it is taken as it stands
        and judged again on the way up (module doc)."""
        if wait:
            self._waiting.add(k)
            self._clear_since.pop(k, None)
            return True
        if k not in self._waiting:
            return False
        since = self._clear_since.setdefault(k, t)
        if t - since < self.params.gap_confirm - 1e-9:  # (ticks' float times)
            return True  # not yet taken: what the gap may hide has not had the time to show
        self._waiting.discard(k)
        del self._clear_since[k]
        if at_line:
            self._committed.add(k)  # the gap is taken: the car goes, committed
        return False

    def _box_rules(self, j: Junction) -> bool:
        """Whether the car looks at `j`'s box and oncoming traffic at all: before a left
        turn or a U-turn, or at a stop-sign junction."""
        return j.manoeuvre in (Manoeuvre.LEFT, Manoeuvre.U_TURN) or \
            j.control is Control.STOP_SIGNS

    def _box_taken(self, k: int, tracks: Sequence[Track]) -> bool:
        """Whether a vehicle track is in junction `k`'s box, or on its way in, and not
        moving the car's way (`_in_box`), where the car looks at the box (`_box_rules`)."""
        j = self.road.junctions[k]
        xy, vel = _vehicles(tracks)
        return self._box_rules(j) and len(xy) > 0 and \
            bool(np.any(self._in_box(j, self._line_out[k], xy, vel)))

    def _must_wait(self, k: int, tracks: Sequence[Track]) -> bool:
        """Whether a vehicle in junction `k`'s box, or an oncoming one before a left turn
        or U-turn, keeps the car at its line (module doc, giving way)."""
        j = self.road.junctions[k]
        xy, vel = _vehicles(tracks)
        if not len(xy) or not self._box_rules(j):
            return False
        wait = bool(np.any(self._in_box(j, self._line_out[k], xy, vel)))
        if j.manoeuvre in (Manoeuvre.LEFT, Manoeuvre.U_TURN):
            soon = self._oncoming_soon(j, xy, vel)
            if j.control is Control.STOP_SIGNS:
                soon &= self._runs_its_line(j, self._line_out[k], xy, vel,
                                            _half_lengths(tracks))
            wait = wait or bool(np.any(soon))
        return wait

    def _runs_its_line(self, j: Junction, line_out: float, xy: np.ndarray, vel: np.ndarray,
                       half_length: np.ndarray) -> np.ndarray:
        """The oncoming tracks (on the far arm) that can no longer stop at their own stop
        line, `line_out` [m] from the centre, at ``commit_decel``: moving towards the box
        faster than v = sqrt(2 commit_decel d), d [m] from the front bumper (the centre less
        `half_length` [m]) to the line (0 once over it). The others stop there and go in
        the order of arrival."""
        p = self.params
        along, _, v_along, _ = self._frame(j, xy, vel)
        towards = -v_along  # [m/s]
        room = np.maximum(along - half_length - line_out, 0.0)  # [m] front to its line
        out: np.ndarray = (towards > p.moving) & \
            (towards * towards > 2.0 * p.commit_decel * room)
        return out

    def _frame(self, j: Junction, xy: np.ndarray,
               vel: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Along / left of the approach's direction, from the junction's centre, for the
        positions, and the velocities' components the same way."""
        f = np.array([math.cos(j.heading), math.sin(j.heading)])
        left = np.array([-f[1], f[0]])
        rel = xy - np.array([j.x, j.y])
        return rel @ f, rel @ left, vel @ f, vel @ left

    def _in_box(self, j: Junction, line_out: float, xy: np.ndarray,
                vel: np.ndarray) -> np.ndarray:
        """The tracks in the box, or on their way in: past their stop line (within
        `line_out` [m] of the centre) and moving towards the centre, as a car that took its
        turn at an all-way stop does; not those moving the car's way."""
        p = self.params
        along, left, v_along, v_left = self._frame(j, xy, vel)
        inside = (np.abs(along) <= j.half_width) & (np.abs(left) <= j.half_width)
        speed = np.hypot(v_along, v_left)
        moving = speed > p.moving
        past_line = (np.abs(along) <= line_out) & (np.abs(left) <= line_out)
        inwards = along * v_along + left * v_left < 0.0
        my_way = v_along > p.same_way * np.maximum(speed, 1e-9)
        out: np.ndarray = (inside | (past_line & moving & inwards)) & ~(my_way & moving)
        return out

    def _oncoming_soon(self, j: Junction, xy: np.ndarray, vel: np.ndarray) -> np.ndarray:
        p = self.params
        along, left, v_along, _ = self._frame(j, xy, vel)
        towards = -v_along
        on_far_arm = (along > j.half_width) & (along < j.half_width + p.oncoming_reach) & \
            (left > 0.0) & (left < j.half_width + 1.0)
        arrive = (along - j.half_width) / np.maximum(towards, 1e-9)
        coming = (towards > p.moving) & (arrive < p.gap_time)
        about_to = along - j.half_width < p.near_box
        out: np.ndarray = on_far_arm & (coming | about_to)
        return out


class ArrivalOrder:
    """Who came first at one all-way stop, from the tracks (module doc, giving way)."""

    def __init__(self, params: JunctionParams) -> None:
        self.params = params
        self.arrived: float | None = None  # [s] when the car stood at its line
        self.first_seen: dict[int, float] = {}  # track id -> [s] first seen (any place)
        self.waiting_since: dict[int, float] = {}  # track id -> [s] arrival at its line

    def update(self, t: float, j: Junction, line_out: float, standing: bool,
               tracks: Sequence[Track]) -> bool:
        """Whether the car must wait for a vehicle that arrived before it, at time `t` [s];
        `line_out` [m] from the centre to a line, `standing` the car stands at its own."""
        p = self.params
        if standing and self.arrived is None:
            self.arrived = t
        waiting = {tr.id: tr for tr in tracks
                   if tr.cls in (ObjectClass.CAR, ObjectClass.TRUCK) and
                   waits_at_line(j, line_out, tr, p)}
        for tr in tracks:
            self.first_seen.setdefault(tr.id, t)
        for tid in list(self.waiting_since):
            if tid not in waiting:
                del self.waiting_since[tid]  # gone from its line: into the junction
        for tid in waiting:
            if tid not in self.waiting_since:
                already = self.first_seen[tid] == t  # first seen waiting: there before
                self.waiting_since[tid] = -math.inf if already else t
        if self.arrived is None:
            return False
        return any(self._before(waiting[tid], since, j) for tid, since in
                   self.waiting_since.items())

    def _before(self, tr: Track, since: float, j: Junction) -> bool:
        """Whether the vehicle of track `tr`, waiting at its line since `since` [s], goes
        before the car."""
        assert self.arrived is not None
        if since < self.arrived - self.params.tie:
            return True
        if since > self.arrived + self.params.tie:
            return False
        return _on_right(j.heading, _arm_heading(j, tr))


def _vehicles(tracks: Sequence[Track]) -> tuple[np.ndarray, np.ndarray]:
    """(positions (N, 2) [m], velocities (N, 2) [m/s]) of the vehicle tracks (map frame)."""
    vehicles = [tr for tr in tracks if tr.cls in (ObjectClass.CAR, ObjectClass.TRUCK)]
    return (np.array([[tr.x, tr.y] for tr in vehicles]).reshape(-1, 2),
            np.array([[tr.vx, tr.vy] for tr in vehicles]).reshape(-1, 2))


def _half_lengths(tracks: Sequence[Track]) -> np.ndarray:
    """[m] (N,) half the length of the vehicle tracks, in `_vehicles`' order."""
    return np.array([0.5 * tr.length for tr in tracks
                     if tr.cls in (ObjectClass.CAR, ObjectClass.TRUCK)], dtype=float)


def waits_at_line(j: Junction, line_out: float, tr: Track, p: JunctionParams) -> bool:
    """Whether track `tr` stands at the stop line of one of `j`'s arms, first of its queue:
    in the arm's inbound lane, its centre `line_zone_near` to `line_zone_far` beyond the
    line, `line_out` [m] from the centre (module doc)."""
    if math.hypot(tr.vx, tr.vy) >= p.moving:
        return False
    rel_x, rel_y = tr.x - j.x, tr.y - j.y
    for k in range(4):
        out = j.heading + math.pi + 0.5 * math.pi * k  # the arm's outward direction
        c, s = math.cos(out), math.sin(out)
        along = rel_x * c + rel_y * s  # [m] out from the centre
        left_of_inbound = rel_x * s - rel_y * c  # [m] inbound travel is -out; its lane: right
        beyond = along - line_out
        if p.line_zone_near <= beyond <= p.line_zone_far and \
                0.0 < -left_of_inbound < j.half_width:
            return True
    return False


def _arm_heading(j: Junction, tr: Track) -> float:
    """[rad] the inbound direction of travel of the arm the track stands on."""
    out = math.atan2(tr.y - j.y, tr.x - j.x)
    k = round(math.remainder(out - j.heading - math.pi, 2.0 * math.pi) / (0.5 * math.pi))
    return j.heading + math.pi + 0.5 * math.pi * k + math.pi


def _on_right(heading: float, other: float) -> bool:
    """Whether a vehicle travelling `other` [rad] comes from the right of one travelling
    `heading` [rad]: it travels 90 deg to the left of it."""
    return abs(math.remainder(other - heading - 0.5 * math.pi, 2.0 * math.pi)) < 0.5
