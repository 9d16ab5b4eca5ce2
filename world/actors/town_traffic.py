"""Town traffic: NPC cars that keep to the rules along their own routes.

An NPC in a town drives its route road (`world.map.town.compile_route`) at its scripted speed
(`NpcMotion`), capped each step by `TownDriver.speed_cap`, the least of:

- **signals**: a red light ahead, or a yellow one it can stop for at ``STOP_DECEL``, makes
  it stop with its front bumper ``STOP_MARGIN`` before the line, along the braking curve
  ``v = sqrt(2 b d)``, b = ``STOP_DECEL``, d the distance left;
- **stop signs**: it stops at the line (slower than ``STOP_SPEED``), stands ``STOP_DWELL``,
  then goes on once no other vehicle's centre is inside the junction's box;
- **turns**: ``v = sqrt(TURN_LATERAL_ACCEL / curvature)`` on a turn's arc, braked for ahead
  of it by the braking curve;
- **the vehicle ahead**: any vehicle (other NPCs, the ego) whose centre is on its route
  ahead, within its lane (``FOLLOW_LANE_HALF`` of the reference line), is kept at a
  standstill gap of ``FOLLOW_GAP`` plus ``FOLLOW_HEADWAY`` seconds of speed, again by the
  braking curve;
- **the route's end** (the next junction's stop line): it stops there and stays.

Lines, turns and vehicles count within ``LOOK_AHEAD``. The cap only lowers the speed;
`NpcMotion` speeds up again at its ``CAP_ACCEL`` when it lifts. These are scripted drivers
on ground truth (the world's own NPCs), not a stack: they read the light's lamp from its
timing and other cars' true poses.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from world.hdmap import LightColour, RoadMap, StopSign, TrafficLight
from world.map.signals import light_colour
from world.spec import TrafficLightSpec

STOP_DECEL = 2.5  # [m/s^2] the braking curve to a stop line or a car ahead
STOP_MARGIN = 0.5  # [m] front bumper short of the stop line
STOP_DWELL = 1.5  # [s] standing at a stop sign
STOP_SPEED = 0.3  # [m/s] below this at the line counts as stopped
TURN_LATERAL_ACCEL = 2.0  # [m/s^2] on a turn's arc
FOLLOW_GAP = 4.0  # [m] bumper to bumper at a standstill
FOLLOW_HEADWAY = 1.2  # [s] of its own speed, added to the standstill gap
FOLLOW_LANE_HALF = 1.5  # [m] how far off its lane's centre a vehicle counts as ahead
LOOK_AHEAD = 60.0  # [m] how far ahead lines, turns and vehicles count
FOLLOW_REACH = LOOK_AHEAD + FOLLOW_LANE_HALF + 20.0  # [m] a vehicle farther than this from
#   the route's point at the NPC's station cannot be ahead within LOOK_AHEAD and within
#   FOLLOW_LANE_HALF of the line (the route between two stations is no shorter than the
#   straight line between them; 20 m spare for projections clipped at a piece's end), so
#   it is not projected at all: the same answer without the cost


FloatArray = NDArray[np.float64]


@dataclass(slots=True)
class _StopLine:
    """A stop line on the NPC's route and what the NPC knows of it."""

    s: float  # [m] station of the line on the NPC's route
    light: TrafficLightSpec | None  # its signal plan; None: a stop sign
    box: tuple[float, float, float]  # [m] (x, y, half width) of the junction's box
    stood_since: float | None = None  # [s] when it came to a stop at a stop sign
    passed: bool = False  # the front bumper is over the line


class TownDriver:
    """The rules one NPC keeps on its route `road` (module doc), whose lights have the
    signal plans `signals` (by stop-line station)."""

    def __init__(self, road: RoadMap, signals: Sequence[TrafficLightSpec],
                 half_length: float) -> None:
        """`half_length` [m]: the NPC's centre to its front bumper."""
        self.road = road
        self.half_length = half_length
        boxes = {j.s_stop: (j.x, j.y, j.half_width) for j in road.junctions}
        plans = {light.s: light for light in signals}
        self._lines = [
            _StopLine(f.s, plans[f.s] if isinstance(f, TrafficLight) else None,
                      boxes.get(f.s, (0, 0, 0)))
            for f in road.features if isinstance(f, StopSign | TrafficLight)
        ]
        # the turn arcs: (start station, end station, curvature)
        self._arcs = [(p.s0, p.s0 + p.length, abs(p.curvature))
                      for p in road.pieces if p.curvature != 0.0]

    def speed_cap(self, t: float, s: float, speed: float, others: FloatArray,
                  other_half_lengths: FloatArray) -> float:
        """[m/s] the most this NPC may drive now at station s and `speed`; `others` (N, 2)
        are the other vehicles' centres, with their half lengths."""
        front = s + self.half_length
        cap = min(self._line_cap(t, front, speed, others), self._turn_cap(s),
                  _braking_speed(max(self.road.length - front, 0.0)))
        return min(cap, self._follow_cap(s, speed, others, other_half_lengths))

    def _line_cap(self, t: float, front: float, speed: float, others: FloatArray) -> float:
        """[m/s] the braking speed to the first line ahead it must stop at (signals, signs)."""
        cap = math.inf
        for line in self._lines:
            if line.passed:
                continue
            distance = line.s - STOP_MARGIN - front
            if distance < -STOP_MARGIN:  # the front is over the line: it has gone
                line.passed = True
                continue
            if distance > LOOK_AHEAD:
                break
            if self._must_stop(line, t, distance, speed, others):
                cap = min(cap, _braking_speed(max(distance, 0.0)))
        return cap

    def _must_stop(self, line: _StopLine, t: float, distance: float, speed: float,
                   others: FloatArray) -> bool:
        """Whether it must stop at `line`, `distance` [m] ahead of the front bumper's stop."""
        if line.light is not None:
            colour = light_colour(line.light, t)
            # yellow: stop if it can at STOP_DECEL (with 1 m^2/s^2 of slack), else go
            if colour is LightColour.YELLOW:
                return speed * speed <= 2.0 * STOP_DECEL * max(distance, 0.0) + 1.0
            return colour is LightColour.RED
        if line.stood_since is None:
            if distance < 1.0 and speed < STOP_SPEED:
                line.stood_since = t
            return True
        return t - line.stood_since < STOP_DWELL or _box_occupied(line.box, others)

    def _turn_cap(self, s: float) -> float:
        """[m/s] the lowest turn speed ahead, each braked for from its arc's start."""
        cap = math.inf
        for s0, s1, curvature in self._arcs:
            if s > s1 or s0 - s > LOOK_AHEAD:
                continue
            v_turn = math.sqrt(TURN_LATERAL_ACCEL / curvature)
            cap = min(cap, math.sqrt(v_turn * v_turn + 2.0 * STOP_DECEL * max(s0 - s, 0.0)))
        return cap

    def _follow_cap(self, s: float, speed: float, others: FloatArray,
                    other_half_lengths: FloatArray) -> float:
        """[m/s] the braking speed to the following distance behind the nearest vehicle."""
        x, y, _ = self.road.line.pose_one(s, 0.0)
        near = np.hypot(others[:, 0] - x, others[:, 1] - y) < FOLLOW_REACH
        if not near.any():
            return math.inf
        others, other_half_lengths = others[near], other_half_lengths[near]
        stations, offsets = self.road.local_coordinates(others)
        ahead = (stations > s) & (stations - s < LOOK_AHEAD) & (np.abs(offsets) < FOLLOW_LANE_HALF)
        if not ahead.any():
            return math.inf
        gaps = stations[ahead] - s - self.half_length - other_half_lengths[ahead]
        room = float(gaps.min()) - FOLLOW_GAP - FOLLOW_HEADWAY * speed
        return _braking_speed(max(room, 0.0))


def _braking_speed(distance: float) -> float:
    """[m/s] the speed from which STOP_DECEL stops in `distance` [m]."""
    return math.sqrt(2.0 * STOP_DECEL * distance)


def _box_occupied(box: tuple[float, float, float], others: FloatArray) -> bool:
    """Whether any centre of `others` (N, 2) [m] is inside the square `box`."""
    x, y, half = box
    if len(others) == 0 or half == 0.0:
        return False
    inside = (np.abs(others[:, 0] - x) < half) & (np.abs(others[:, 1] - y) < half)
    return bool(inside.any())
