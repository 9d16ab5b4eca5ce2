"""The DECS events for the ACC layer, from the HD map and what perception found: the exit
ramp, a stop sign, a pedestrian at a crosswalk, a speed bump, a flat tyre.

Positions are stations [m] along the route's reference line (the car's centre s, its front
bumper f, its axles); tracks are in the map frame. Each tick
(`EventMonitor.update`, parameters `EventParams`):

- off_ramp: the segment where the posted limit in force is read is of zone `ramp` (the
  paper's [Off_Ramp]): the front bumper as the speed plan places it
  (`planner.speed_planning.SpeedPlanner.front_station`, passed as ``limit_station``), so
  that the ramp's event and its lower limit begin (and end) on the same tick, and the ACC
  goes from its mode before the ramp straight into OFF_RAMP (no SPEED_LIMIT for the time
  the bumper takes to the centre).
- stop_sign: the next stop line L of the map ahead, once perception has confirmed its sign
  (`see_signs`: a camera stop sign, placed on the map, near the line and right of the
  route), from ``approach(v)`` before it until the car has stood (below ``stopped_speed``)
  for ``stop_hold`` with its front bumper 0 to ``stop_zone`` before the line and no vehicle
  right in front of it (`planner.queue`: a stop behind a car queued at the line is not the
  stop at the line, however long, nor however near the line the car's estimate puts it; the
  car moves up and stops at the line itself); the
  line is then done until the front bumper is past it. The car aims to stand
  ``stop_margin`` plus the law's margin before the line (`stop_distance` = L - f -
  stop_margin).
- pedestrian: the next crosswalk ahead, from ``approach(v)`` before it while the front
  bumper has not reached it, with a pedestrian track on it or within ``crossing_margin`` of
  it along the route whose centre is inside the lane kept widened by ``lane_margin`` on each
  side, now or ``look_ahead`` ahead at its velocity, or crosses the lane's centre line in
  between; the car stops ``crossing_stop`` before the crosswalk and waits until it is clear.
  It also yields to a pedestrian on the crosswalk who walks across the road towards the
  lane kept (at ``walk_in`` or faster, from within ``waiting_reach`` beyond its edges) while
  a stop at ``a_comf`` is still left, and goes on yielding while one walks in: a pedestrian
  who steps off the far kerb enters the lane's band only a few seconds later, when the stop
  left is a hard one (or none), and the car would brake hard or pass close in front.
  The car's station is known only to its pose estimate's 1-sigma (``station_sigma``: a
  consumer receiver's bias along the route, which the camera's lane does not correct, 1.2 m
  1-sigma): the tracks are placed on the map with the same error, so a pedestrian on the
  crosswalk may appear up to ``station_sigmas`` x that before or beyond it. Along the route
  the crosswalk's reach is widened by that much on each side, and the car stops that much
  before it in its estimate (at least ``crossing_stop``), so that where it truly stands is
  still the law's margin before the crosswalk.
- a pedestrian waiting (`EventMonitor.waiting`, no event: the speed plan's lower crossing
  speed, `planner.speed_planning`): a crosswalk ahead of the front bumper with a pedestrian
  track on it or within ``crossing_margin`` of it along the route (widened by the station's
  uncertainty as above), and across no farther
  than ``waiting_reach`` beyond the lane kept's edges (at the kerb, or crossing the other
  lanes): it may step into the lane, and its track shows a walk only some 0.9 s after the
  first step.
- speed_bump: from ``approach(v)`` before a bump's near edge (front axle) until the rear
  axle is ``bump_margin`` past its far edge (held once entered: braking for it shrinks
  ``approach(v)``, and the event ended and began again for a tick); the speed at the bump
  is its pass speed less ``bump_undershoot`` (at least 0.5 m/s), to be reached by the front
  axle ``bump_margin`` before the near edge.
- flat: a flat tyre detected from the car's own signals; pulled_over once the motion layer
  has brought the car onto the shoulder.

``approach(v) = v^2 / (2 a_comf) + approach_extra``: the distance braking at a_comf needs,
plus room to settle.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from perception.messages import EgoState, ObjectClass, SignDetection, Track
from planner.fsm.acc import NO_EVENTS, AccEvent
from planner.limits import A_COMF
from planner.queue import queued
from world.frames import VehicleInfo, kph
from world.hdmap import NEAR_WINDOW, Crosswalk, RoadMap, SpeedBump, StopSign, Zone


@dataclass(frozen=True, slots=True)
class EventParams:
    a_comf: float = A_COMF  # [m/s^2] approach braking
    approach_extra: float = 30.0  # [m] added to the braking distance: room to settle
    stop_margin: float = 0.5  # [m] stop this much (+ the law's margin) before a line
    stopped_speed: float = 0.1  # [m/s] below this the car stands at a stop line
    stop_hold: float = 1.5  # [s] standing this long at the line completes the stop
    stop_zone: float = 4.0  # [m] the front bumper within this before the line counts
    crossing_margin: float = 1.0  # [m] along the route, a pedestrian this near counts
    lane_margin: float = 1.5  # [m] across, a pedestrian this far beyond the lane's edges counts
    look_ahead: float = 2.0  # [s] a pedestrian walking into the lane within this counts
    crossing_stop: float = 1.0  # [m] stop this much (+ the law's margin) before a crosswalk
    station_sigmas: float = 2.5  # [-] a crosswalk's reach along the route is widened, and its
    #   stop is at least, this many 1-sigmas of the car's station (one-sided 99.4 %): under
    #   a consumer receiver (1.2 m 1-sigma) the estimate may be 2.4 m off along the route,
    #   and a pedestrian on the crosswalk's near edge then appears 1.2 m short of it
    law_margin: float = 1.0  # [m] the stop law's margin before the stop point
    #   (`planner.acc_control.AccControlParams.margin`)
    walk_in: float = 0.5  # [m/s] a pedestrian walking towards the lane kept at least this
    #   fast across the road, within ``waiting_reach`` of it, is crossing (the yield)
    waiting_reach: float = 6.0  # [m] across, a pedestrian at a crosswalk this far beyond the
    #   lane's edges waits to cross: from the far kerb of a road of one lane each way (3.5 m
    #   lanes, 2 m shoulders: 5.5 m) it walks into the lane in under 3 s at 8 km/h
    bump_margin: float = 1.0  # [m] pass speed from this before a bump to this past it (the
    #   speed_bumps criterion's reach)
    bump_undershoot: float = kph(0.5)  # [m/s] aim this far below the pass speed
    sign_match: float = 5.0  # [m] a seen sign this near a stop line (along) is its sign


@dataclass(frozen=True, slots=True)
class Events:
    """The events that hold now, and the distances their laws need."""

    active: frozenset[AccEvent] = NO_EVENTS  # this module's and `planner.junctions`'
    pulled_over: bool = False  # on the shoulder, the pull-over done (a flat tyre's stop)
    stop_distance: float = math.inf  # [m] front bumper to where the car must stand
    bump_distance: float = math.inf  # [m] front axle to where it must be at bump_speed
    bump_speed: float = math.inf  # [m/s] the speed to cross the bump at

    def holds(self, event: AccEvent) -> bool:
        """Whether `event` holds now."""
        return event in self.active


class EventMonitor:
    """The events of one run (it remembers the stop lines done and the signs seen)."""

    def __init__(self, road: RoadMap, vehicle: VehicleInfo,
                 params: EventParams | None = None) -> None:
        self.road, self.vehicle = road, vehicle
        self.params = params if params is not None else EventParams()
        f = road.features
        self.stop_lines = sorted(x.s for x in f if isinstance(x, StopSign))
        self.crosswalks = sorted((x for x in f if isinstance(x, Crosswalk)), key=lambda c: c.s)
        self.bumps = sorted((x for x in f if isinstance(x, SpeedBump)), key=lambda b: b.s)
        self.confirmed: set[float] = set()  # stop lines whose sign perception saw
        self.done: set[float] = set()  # stop lines stopped at, not yet passed
        self._standing_since: float | None = None
        self._yield_at: float | None = None  # [m] the crosswalk yielded at to a pedestrian
        #   walking in, held while one walks in (`_yields`)
        self._bump_at: float | None = None  # [m] the station of the bump approached: held
        #   until it is passed, the approach shrinking with the speed it sheds
        self._station: float | None = None  # [m] the car's centre at the last update: the
        #   signs seen are placed on the stretch ahead of it (a town route crossing itself
        #   passes a point twice: `world.hdmap.ReferenceLine.project`)

    def confirm_sign(self, line_s: float) -> None:
        """Perception found the sign of the stop line at `line_s` [m]."""
        self.confirmed.add(line_s)

    def see_signs(self, signs: Sequence[SignDetection], pose: EgoState) -> None:
        """Match the camera's stop signs (vehicle frame at `pose`, the pose the frame was
        taken in) with the map's: a sign right of the route whose station is within the larger
        of ``sign_match`` and 20 % of its range [m] of a stop line confirms that line."""
        p = self.params
        c, s = math.cos(pose.heading), math.sin(pose.heading)
        near = None if self._station is None else self._station + NEAR_WINDOW  # the 60 m ahead
        for d in signs:
            if d.kind != "stop":
                continue
            xy = (pose.x + c * d.x - s * d.y, pose.y + s * d.x + c * d.y)
            station, offset = (float(a) for a in self.road.local_coordinates(xy, near))
            tolerance = max(p.sign_match, 0.2 * d.range)
            for line in self.stop_lines:
                if abs(station - line) <= tolerance and offset < 0.0:
                    self.confirmed.add(line)

    def update(self, t: float, station: float, v: float, lane_offset: float, lane_width: float,
               tracks: Sequence[Track] = (), flat: bool = False,
               pulled_over: bool = False, limit_station: float | None = None,
               station_sigma: float = 0.0) -> Events:
        """The events at time `t` [s] for the car's centre at `station` [m] with speed `v`
        [m/s]; `lane_offset` [m] of the lane kept's centre from the reference line there
        (left +) and its `lane_width` [m]; `tracks` the confirmed tracks (map frame); `flat`
        a flat tyre detected, `pulled_over` the car on the shoulder; `limit_station` [m]
        where the speed plan reads the posted limit (its front bumper; by default `station`
        + the front overhang); `station_sigma` [m] the 1-sigma of `station` (the pose
        estimate's, `perception.messages.EgoState.position_sigma`)."""
        p = self.params
        front = station + self.vehicle.front_overhang
        self._station = station
        limit_station = front if limit_station is None else limit_station
        approach = v * v / (2.0 * p.a_comf) + p.approach_extra
        stop = self._stop_sign(t, front, v, approach,
                               lambda: queued(self.road, station, front, lane_offset, lane_width,
                                              tracks))
        crossing = self._crossing(front, v, approach, lane_offset, lane_width, tracks,
                                  p.station_sigmas * station_sigma)
        bump = self._bump(station, approach)
        zone = self.road.cross_section_at(limit_station).zone
        happening = {AccEvent.OFF_RAMP: zone is Zone.RAMP, AccEvent.STOP_SIGN: stop is not None,
                     AccEvent.PEDESTRIAN: crossing is not None,
                     AccEvent.SPEED_BUMP: bump is not None, AccEvent.FLAT: flat}
        return Events(
            active=frozenset(e for e, holds in happening.items() if holds),
            pulled_over=pulled_over,
            stop_distance=min(x for x in (stop, crossing, math.inf) if x is not None),
            bump_distance=bump[0] if bump is not None else math.inf,
            bump_speed=bump[1] if bump is not None else math.inf,
        )

    def _stop_sign(self, t: float, front: float, v: float, approach: float,
                   in_queue: Callable[[], bool]) -> float | None:
        """[m] to where the car must stand for the next stop line, or None; a standstill
        counts towards the stop only at the line itself, not in a queue (`in_queue()`: a
        vehicle right in front of the car, `planner.queue`)."""
        p = self.params
        self.done = {s for s in self.done if s > front - 1.0}  # passed: forget
        line = next((s for s in self.stop_lines if s > front - 1.0 and s not in self.done), None)
        if line is None or line - front > approach or line not in self.confirmed:
            self._standing_since = None
            return None
        at_line = 0.0 <= line - front <= p.stop_zone
        if v < p.stopped_speed and at_line and not in_queue():
            self._standing_since = t if self._standing_since is None else self._standing_since
            if t - self._standing_since >= p.stop_hold:
                self.done.add(line)
                self._standing_since = None
                return None
        else:
            self._standing_since = None
        return line - front - p.stop_margin

    def _crossing(self, front: float, v: float, approach: float, lane_offset: float,
                  lane_width: float, tracks: Sequence[Track], slack: float) -> float | None:
        """[m] from the front bumper to where the car must stand for a pedestrian at the next
        crosswalk, or None (module doc); `v` [m/s] the car's speed; `slack` [m] how far off
        along the route the car's station (and the tracks placed with it) may be."""
        p = self.params
        cw = next((c for c in self.crosswalks
                   if front < c.s and c.s - front - slack <= approach), None)
        walkers = [tr for tr in tracks if tr.cls is ObjectClass.PEDESTRIAN]
        if cw is None or not walkers:
            self._yield_at = None
            return None
        xy = np.array([[tr.x, tr.y] for tr in walkers])
        ahead = xy + p.look_ahead * np.array([[tr.vx, tr.vy] for tr in walkers])
        s_now, d_now = self.road.local_coordinates(xy)
        _, d_next = self.road.local_coordinates(ahead)
        reach = p.crossing_margin + slack
        on = (s_now >= cw.s - reach) & (s_now <= cw.s + cw.width + reach)
        half = 0.5 * lane_width + p.lane_margin
        lateral = np.minimum(np.abs(d_now - lane_offset), np.abs(d_next - lane_offset)) <= half
        crossing_between = np.sign(d_now - lane_offset) != np.sign(d_next - lane_offset)
        stand = cw.s - front - max(p.crossing_stop, slack)
        if np.any(on & (lateral | crossing_between)) or self._yields(
                cw.s, v, stand, on & self._walking_in(d_now, d_next, lane_offset, lane_width)):
            return stand
        return None

    def _walking_in(self, d_now: NDArray[np.float64], d_next: NDArray[np.float64],
                    lane_offset: float, lane_width: float) -> NDArray[np.bool_]:
        """Which pedestrians, `d_now` [m] across now and `d_next` ``look_ahead`` ahead, walk
        towards the lane kept (centre `lane_offset` [m], `lane_width` [m]) at ``walk_in`` or
        faster from within ``waiting_reach`` beyond its edges: crossing the road towards it."""
        p = self.params
        towards = np.sign(lane_offset - d_now) * (d_next - d_now) / p.look_ahead
        near = np.abs(d_now - lane_offset) <= 0.5 * lane_width + p.waiting_reach
        return near & (towards >= p.walk_in)

    def _yields(self, cw_s: float, v: float, stand: float, walking_in: NDArray[np.bool_]) -> bool:
        """Whether the car yields at the crosswalk at `cw_s` [m] to a pedestrian crossing the
        road towards its lane (`walking_in`, module doc) while a comfortable stop, at most
        ``a_comf`` from the speed v [m/s] within `stand` [m] (less the stop law's margin),
        is left; once it yields it goes on yielding while one walks in."""
        if not np.any(walking_in):
            self._yield_at = None
            return False
        p = self.params
        if self._yield_at != cw_s and v * v <= 2.0 * p.a_comf * max(stand - p.law_margin, 0.0):
            self._yield_at = cw_s
        return self._yield_at == cw_s

    def waiting(self, station: float, lane_offset: float, lane_width: float,
                tracks: Sequence[Track], station_sigma: float = 0.0) -> frozenset[float]:
        """The stations [m] of the crosswalks ahead of the front bumper of a car whose centre
        is at `station` [m] where a pedestrian track waits (module doc): on the crosswalk or
        within ``crossing_margin`` of it along the route, and across within ``waiting_reach``
        of the edges of the lane kept (centre `lane_offset` [m] from the reference line, left
        +, `lane_width` [m]); `tracks` in the map frame; `station_sigma` [m] the 1-sigma of
        `station` (`update`)."""
        p = self.params
        front = station + self.vehicle.front_overhang
        ahead = [c for c in self.crosswalks if front < c.s]
        walkers = [tr for tr in tracks if tr.cls is ObjectClass.PEDESTRIAN]
        if not ahead or not walkers:
            return frozenset()
        s_now, d_now = self.road.local_coordinates(np.array([[tr.x, tr.y] for tr in walkers]))
        near = np.abs(np.asarray(d_now) - lane_offset) <= 0.5 * lane_width + p.waiting_reach
        s_near = np.asarray(s_now)[near]
        reach = p.crossing_margin + p.station_sigmas * station_sigma
        return frozenset(c.s for c in ahead
                         if np.any((s_near >= c.s - reach) & (s_near <= c.s + c.width + reach)))

    def _bump(self, station: float, approach: float) -> tuple[float, float] | None:
        p = self.params
        v = self.vehicle
        front_axle, rear_axle = station + v.front_axle, station - v.rear_axle
        for b in self.bumps:
            near, far = b.s - 0.5 * b.length, b.s + 0.5 * b.length
            if rear_axle > far + p.bump_margin:
                continue
            if near - front_axle > approach and b.s != self._bump_at:
                self._bump_at = None
                return None
            self._bump_at = b.s
            return near - p.bump_margin - front_axle, max(b.pass_speed - p.bump_undershoot, 0.5)
        self._bump_at = None
        return None
