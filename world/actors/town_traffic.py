"""Town traffic: NPC cars that keep to the rules along their own routes.

An NPC in a town drives its route road (`world.map.town.compile_route`) at its scripted speed
(`NpcMotion`), capped each step by `TownDriver.speed_cap`, the least of:

- **signals**: a red light ahead, or a yellow one it can stop for at ``STOP_DECEL``, makes
  it stop with its front bumper ``STOP_MARGIN`` before the line, along the braking curve
  ``v = sqrt(2 b d)``, b = ``STOP_DECEL``, d the distance left. Turning left (or a U-turn)
  on green, it also stops at the line while an oncoming vehicle will reach the junction's
  box within ``LEFT_GAP``, or is in the box coming its way. The time to the box is the
  sooner of its own speed's and a pull-away's from rest at ``PULL_AWAY``: a vehicle
  standing at the opposing line, or queued behind it within ``PULL_AWAY LEFT_GAP^2 / 2``
  of the box, goes on the same green and has the priority (oncoming straight traffic goes
  first), so it is waited for too; not one that itself turns across at its next junction
  (`Others.turns_across`: opposing left turns pass each other);
- **stop signs** (all-way stops): it stops at the line (slower than ``STOP_SPEED`` with
  its front within 1 m of its stop point), which makes it arrive there
  (`world.actors.all_way_stop`: first to stop, first to go, ties to the right; the ego
  arrives too when it stands at its line, `StopZones`); it stands at least
  ``STOP_DWELL``, then goes on when it is its turn and the box is clear: no other vehicle's
  centre inside the junction's box, nor one on its way in (moving towards the box's centre
  faster than ``STOP_SPEED``, its front bumper over its own stop line or within
  ``STOP_ZONE`` before it: one that has just taken its turn and moved off its line, which
  left the order, but is not in the box yet). It leaves the order when its front is over
  the line. A car queued
  behind another stops behind it (the vehicle ahead, below), moves up when it leaves,
  and makes its own stop at the line;
- **turns**: ``v = sqrt(TURN_LATERAL_ACCEL / curvature)`` on a turn's arc, braked for ahead
  of it by the braking curve;
- **the vehicle ahead**: any vehicle (other NPCs, the ego) whose centre is within
  ``FOLLOW_LANE_HALF`` of its route's line ahead of it (within ``LOOK_AHEAD``; the line is
  sampled every ``SAMPLE_STEP`` over a window ahead, so a route that passes a place twice
  sees only the pass ahead, and vehicles behind never count), is kept at a standstill gap
  of ``FOLLOW_GAP`` plus ``FOLLOW_HEADWAY`` seconds of speed, again by the braking curve;
- **the route's end** (the next junction's stop line): it stops there and has *arrived*:
  it leaves the town (`TownDriver.arrived`; its body is taken out of the world) rather
  than stand in the lane for the rest of the run.

Lines, turns and vehicles count within ``LOOK_AHEAD``. The cap only lowers the speed;
`NpcMotion` speeds up again at its ``CAP_ACCEL`` when it lifts. These are scripted drivers
on ground truth (the world's own NPCs), not a stack: they read the light's lamp from its
timing and other cars' true poses and velocities.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from world.actors.all_way_stop import AllWayStop
from world.hdmap import Control, Junction, LightColour, Manoeuvre, RoadMap, StopSign, TrafficLight
from world.map.signals import light_colour
from world.spec import TrafficLightSpec

STOP_DECEL = 2.5  # [m/s^2] the braking curve to a stop line or a car ahead
STOP_MARGIN = 0.5  # [m] front bumper short of the stop line
STOP_DWELL = 1.5  # [s] standing at a stop sign
STOP_SPEED = 0.3  # [m/s] below this at the line counts as stopped
STOP_ZONE = 4.0  # [m] the ego stands at its line with its front bumper this near it
EGO_STOPPED = 0.1  # [m/s] ... and slower than this (the stack's own "stood" speed, so that
#   the world does not see it arrive before it knows it has)
TURN_LATERAL_ACCEL = 2.0  # [m/s^2] on a turn's arc
FOLLOW_GAP = 4.0  # [m] bumper to bumper at a standstill
FOLLOW_HEADWAY = 1.2  # [s] of its own speed, added to the standstill gap
FOLLOW_LANE_HALF = 1.5  # [m] how far off its lane's centre a vehicle counts as ahead
LOOK_AHEAD = 60.0  # [m] how far ahead lines, turns and vehicles count
SAMPLE_STEP = 0.5  # [m] the route's line ahead is sampled this often for the vehicle ahead
WINDOW = LOOK_AHEAD + 20.0  # [m] the sampled stretch, renewed when 20 m of it is behind
FOLLOW_REACH = LOOK_AHEAD + FOLLOW_LANE_HALF + 20.0  # [m] a vehicle farther than this from
#   the NPC's centre cannot be within FOLLOW_LANE_HALF of its line within LOOK_AHEAD (the
#   route between two stations is no shorter than the straight line between them)
LEFT_GAP = 6.0  # [s] an oncoming vehicle this near the box in time is waited for
PULL_AWAY = 1.5  # [m/s^2] a standing oncoming vehicle's pull-away to the box (as a town
#   driver's own, `world.actors.behaviour.CAP_ACCEL`)
ONCOMING_REACH = 80.0  # [m] beyond the box, how far out oncoming vehicles count
MOVING = 0.5  # [m/s] slower than this, a vehicle is not moving
ARRIVED = 1.0  # [m] the front this near the route's end, standing: it has arrived

FloatArray = NDArray[np.float64]


@dataclass(slots=True)
class _StopLine:
    """A stop line on the NPC's route and what the NPC knows of it."""

    s: float  # [m] station of the line on the NPC's route
    light: TrafficLightSpec | None  # its signal plan; None: a stop sign
    junction: Junction | None  # the junction it guards (None: a line without one)
    line_out: float = 0.0  # [m] the junction's centre to the line (every arm's: the town
    #   is symmetric)
    stood_since: float | None = None  # [s] when it came to a stop at a stop sign
    passed: bool = False  # the front bumper is over the line


@dataclass(frozen=True, slots=True)
class Others:
    """The other vehicles one NPC minds, at one step (map frame)."""

    xy: FloatArray  # [m] (N, 2) centres
    velocity: FloatArray  # [m/s] (N, 2) velocities over ground
    half_length: FloatArray  # [m] (N,) centre to bumper
    # (N,) whether it turns left or makes a U-turn at its next junction; empty: none does
    turns_across: NDArray[np.bool_] = field(default_factory=lambda: np.zeros(0, dtype=bool))

    def across(self) -> NDArray[np.bool_]:
        """(N,) `turns_across`, all False when not given."""
        if len(self.turns_across) == len(self.xy):
            return self.turns_across
        return np.zeros(len(self.xy), dtype=bool)


def no_others() -> Others:
    """Nobody else on the streets."""
    return Others(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0))


class TownDriver:
    """The rules one NPC (`key`) keeps on its route `road` (module doc), whose lights have
    the signal plans `signals` (by stop-line station); `order` is the town's all-way-stop
    order, shared by every driver."""

    def __init__(self, road: RoadMap, signals: Sequence[TrafficLightSpec],
                 half_length: float, key: str = "npc",
                 order: AllWayStop | None = None) -> None:
        """`half_length` [m]: the NPC's centre to its front bumper."""
        self.road = road
        self.half_length = half_length
        self.key = key
        self.order = order if order is not None else AllWayStop()
        self.arrived = False  # at its route's end: it has left the town
        junctions = {j.s_stop: j for j in road.junctions}
        plans = {light.s: light for light in signals}
        self._lines = [
            _StopLine(f.s, plans[f.s] if isinstance(f, TrafficLight) else None,
                      junctions.get(f.s), _line_out(road, f.s, junctions.get(f.s)))
            for f in road.features if isinstance(f, StopSign | TrafficLight)
        ]
        # the turn arcs: (start station, end station, curvature)
        self._arcs = [(p.s0, p.s0 + p.length, abs(p.curvature))
                      for p in road.pieces if p.curvature != 0.0]
        self._next_arc = 0  # the first arc not yet behind
        self._window_s = -math.inf  # [m] where the sampled stretch starts
        self._samples = np.zeros((0, 2))  # [m] (M, 2) its points
        self._sample_s = np.zeros(0)  # [m] (M,) their stations

    def speed_cap(self, t: float, s: float, speed: float, others: Others) -> float:
        """[m/s] the most this NPC may drive now at station s and `speed`, minding
        `others`."""
        front = s + self.half_length
        end = max(self.road.length - front, 0.0)
        if end < ARRIVED and speed < STOP_SPEED:
            self.arrived = True
        cap = min(self._line_cap(t, front, speed, others), self._turn_cap(s),
                  _braking_speed(end))
        return min(cap, self._follow_cap(s, speed, others))

    def turns_across_next(self) -> bool:
        """Whether it turns left or makes a U-turn at the next junction it has not passed."""
        j = next((line.junction for line in self._lines
                  if not line.passed and line.junction is not None), None)
        return j is not None and _turns_across(j)

    def _line_cap(self, t: float, front: float, speed: float, others: Others) -> float:
        """[m/s] the braking speed to the first line ahead it must stop at (signals, signs)."""
        cap = math.inf
        for line in self._lines:
            if line.passed:
                continue
            distance = line.s - STOP_MARGIN - front
            if distance < -STOP_MARGIN:  # the front is over the line: it has gone
                line.passed = True
                if line.junction is not None:
                    self.order.leave(line.junction.index, self.key)
                continue
            if distance > LOOK_AHEAD:
                break
            if self._must_stop(line, t, distance, speed, others):
                cap = min(cap, _braking_speed(max(distance, 0.0)))
        return cap

    def _must_stop(self, line: _StopLine, t: float, distance: float, speed: float,
                   others: Others) -> bool:
        """Whether it must stop at `line`, `distance` [m] ahead of the front bumper's stop."""
        j = line.junction
        if line.light is not None:
            colour = light_colour(line.light, t)
            # yellow: stop if it can at STOP_DECEL (with 1 m^2/s^2 of slack), else go
            if colour is LightColour.YELLOW:
                return speed * speed <= 2.0 * STOP_DECEL * max(distance, 0.0) + 1.0
            if colour is LightColour.RED:
                return True
            return j is not None and _turns_across(j) and _oncoming(j, others)
        if line.stood_since is None:
            if distance < 1.0 and speed < STOP_SPEED:
                line.stood_since = t
                if j is not None:
                    self.order.arrive(j.index, self.key, j.heading, t)
            return True
        if t - line.stood_since < STOP_DWELL:
            return True
        if j is None:
            return False
        return not self.order.may_go(j.index, self.key, t) or \
            _box_occupied(j, others, line.line_out)

    def _turn_cap(self, s: float) -> float:
        """[m/s] the lowest turn speed ahead, each braked for from its arc's start."""
        cap = math.inf
        while self._next_arc < len(self._arcs) and self._arcs[self._next_arc][1] < s:
            self._next_arc += 1  # stations only grow: the arcs behind stay behind
        for s0, s1, curvature in self._arcs[self._next_arc:]:
            if s0 - s > LOOK_AHEAD:
                break
            if s > s1:
                continue
            v_turn = math.sqrt(TURN_LATERAL_ACCEL / curvature)
            cap = min(cap, math.sqrt(v_turn * v_turn + 2.0 * STOP_DECEL * max(s0 - s, 0.0)))
        return cap

    def _follow_cap(self, s: float, speed: float, others: Others) -> float:
        """[m/s] the braking speed to the following distance behind the nearest vehicle
        within FOLLOW_LANE_HALF of the route's line ahead (sampled, module doc)."""
        if len(others.xy) == 0:
            return math.inf
        x, y, _ = self.road.line.pose_one(s, 0.0)
        near = np.hypot(others.xy[:, 0] - x, others.xy[:, 1] - y) < FOLLOW_REACH
        if not near.any():
            return math.inf
        samples, stations = self._ahead(s)
        xy = others.xy[near]
        d2 = ((xy[:, None, :] - samples[None, :, :]) ** 2).sum(axis=2)  # (N, M)
        nearest = np.argmin(d2, axis=1)
        on_line = d2[np.arange(len(xy)), nearest] < FOLLOW_LANE_HALF ** 2
        ahead = on_line & (stations[nearest] > s)
        if not ahead.any():
            return math.inf
        gaps = stations[nearest][ahead] - s - self.half_length - others.half_length[near][ahead]
        room = float(gaps.min()) - FOLLOW_GAP - FOLLOW_HEADWAY * speed
        return _braking_speed(max(room, 0.0))

    def _ahead(self, s: float) -> tuple[FloatArray, FloatArray]:
        """The route's line sampled from s to LOOK_AHEAD ahead: ([m] (M, 2) points, [m] (M,)
        stations); the sampled window is renewed only when 20 m of it is behind."""
        if s - self._window_s > WINDOW - LOOK_AHEAD or s < self._window_s:
            self._window_s = s
            stations = s + np.arange(0.0, WINDOW + SAMPLE_STEP, SAMPLE_STEP)
            stations = stations[stations <= self.road.length]
            x, y, _ = self.road.line.pose(stations, np.zeros_like(stations))
            self._samples, self._sample_s = np.column_stack([x, y]), stations
        keep = (self._sample_s >= s) & (self._sample_s <= s + LOOK_AHEAD)
        if not keep.any():
            return self._samples[-1:], self._sample_s[-1:]
        return self._samples[keep], self._sample_s[keep]


class StopZones:
    """Where a vehicle on route `road` (the ego's) stands at an all-way stop's line: its
    front bumper 0 to ``STOP_ZONE`` before the line (``STOP_MARGIN`` over it at most),
    within ``FOLLOW_LANE_HALF`` of its lane's centre, slower than ``EGO_STOPPED``."""

    def __init__(self, road: RoadMap) -> None:
        self.junctions = [j for j in road.junctions if j.control is Control.STOP_SIGNS]
        lines = [road.line.pose_one(j.s_stop, 0.0) for j in self.junctions]
        self._xy = np.array([(x, y) for x, y, _ in lines]).reshape(-1, 2)
        h = np.array([j.heading for j in self.junctions])
        self._forward = np.column_stack([np.cos(h), np.sin(h)])

    def at_line(self, xy: tuple[float, float], half_length: float, speed: float,
                stopped: float = EGO_STOPPED) -> Junction | None:
        """The all-way stop whose line the vehicle with centre `xy` [m], `half_length` [m]
        and `speed` [m/s] stands at (slower than `stopped` [m/s]); None if it stands at
        none (or moves)."""
        if speed >= stopped or not self.junctions:
            return None
        rel = np.asarray(xy) - self._xy
        along = (rel * self._forward).sum(axis=1)
        across = rel[:, 1] * self._forward[:, 0] - rel[:, 0] * self._forward[:, 1]
        gap = -along - half_length  # [m] front bumper to the line
        at = (gap > -STOP_MARGIN) & (gap < STOP_ZONE) & (np.abs(across) < FOLLOW_LANE_HALF)
        k = np.flatnonzero(at)
        return self.junctions[int(k[0])] if len(k) else None


def _braking_speed(distance: float) -> float:
    """[m/s] the speed from which STOP_DECEL stops in `distance` [m]."""
    return math.sqrt(2.0 * STOP_DECEL * distance)


def _turns_across(j: Junction) -> bool:
    return j.manoeuvre in (Manoeuvre.LEFT, Manoeuvre.U_TURN)


def _junction_frame(j: Junction, xy: FloatArray) -> tuple[FloatArray, FloatArray]:
    """([m] along, [m] left) of points `xy` (N, 2) from the junction's centre, in the
    approach's direction."""
    c, s = math.cos(j.heading), math.sin(j.heading)
    rx, ry = xy[:, 0] - j.x, xy[:, 1] - j.y
    return rx * c + ry * s, ry * c - rx * s


def _oncoming(j: Junction, others: Others) -> bool:
    """Whether an oncoming vehicle will reach `j`'s box within LEFT_GAP (at its speed, or
    pulling away from rest at PULL_AWAY: standing at or queued behind its line; not one
    that turns across itself), or is in the box coming this way (module doc)."""
    if len(others.xy) == 0:
        return False
    along, left = _junction_frame(j, others.xy)
    c, s = math.cos(j.heading), math.sin(j.heading)
    towards = -(others.velocity[:, 0] * c + others.velocity[:, 1] * s)  # [m/s]
    far_arm = (along > j.half_width) & (along < j.half_width + ONCOMING_REACH) & \
        (left > 0.0) & (left < j.half_width)
    soon = (along - j.half_width) < LEFT_GAP * towards
    to_box = along - j.half_width - others.half_length  # [m] its front to the box
    pulls_away = (towards > -MOVING) & (to_box < 0.5 * PULL_AWAY * LEFT_GAP ** 2) & \
        ~others.across()
    in_box = (np.abs(along) <= j.half_width) & (np.abs(left) <= j.half_width)
    coming = towards > MOVING
    return bool(np.any(far_arm & ((coming & soon) | pulls_away)) or
                np.any(coming & in_box))


def _line_out(road: RoadMap, s: float, j: Junction | None) -> float:
    """[m] from junction `j`'s centre back to the stop line at station `s` of `road`, along
    its approach (0 without a junction)."""
    if j is None:
        return 0.0
    x, y, _ = road.line.pose_one(s, 0.0)
    return -((x - j.x) * math.cos(j.heading) + (y - j.y) * math.sin(j.heading))


def _box_occupied(j: Junction, others: Others, line_out: float) -> bool:
    """Whether another vehicle is inside `j`'s box (its centre in the square where the
    streets cross), or on its way in: moving towards the box's centre faster than
    STOP_SPEED with its front bumper within `line_out` [m] + STOP_ZONE of the centre along
    both axes (over its stop line, or within STOP_ZONE before it; every arm's line is
    `line_out` out)."""
    if len(others.xy) == 0:
        return False
    rel = others.xy - np.array([j.x, j.y])
    inside = np.all(np.abs(rel) < j.half_width, axis=1)
    speed = np.hypot(others.velocity[:, 0], others.velocity[:, 1])
    heading = others.velocity / np.maximum(speed, 1e-9)[:, None]
    front = rel + others.half_length[:, None] * heading
    near = np.all(np.abs(front) <= line_out + STOP_ZONE, axis=1)
    inwards = (rel * others.velocity).sum(axis=1) < 0.0
    coming = (speed > STOP_SPEED) & inwards & near
    return bool(np.any(inside | coming))

