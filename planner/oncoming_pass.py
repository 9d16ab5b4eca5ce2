"""Whether a pass through the oncoming lane is safe now: the decision and, when it is not, why.

On a road with one lane each way the only way past a slower or stopped vehicle is the
oncoming lane. Stations s [m] run along the route, speeds [m/s] are along it (an oncoming
vehicle's is its speed towards the car, > 0). The pass is planned as three phases:

1. pull out and close on the slow vehicle, then draw past it: the car covers, relative to
   the slow vehicle (speed v_s), ``gap + its length + the car's length + v_s t_return``
   (the last term: the gap ahead of it that the car returns into, ``t_return`` s of its
   speed, at least ``return_gap``); the car starts at its speed v and speeds up at ``a_pass``
   to the pass speed v_p (the lower of the speed it wants and the posted limit), so
   ``t_rel`` solves ``rel(t) = distance`` with ``rel`` the closing distance under that
   acceleration;
2. return to its own lane: ``t_lane`` s (the lane change's nominal duration) at v_p;
3. ``t_margin`` s more.

The pass takes ``T = t_rel + t_lane + t_margin`` and the car travels ``X = v_s t_rel +
distance + v_p (t_lane + t_margin)`` in it. Two kinds of oncoming vehicle are judged:

- a *tracked* one (speed ``u`` towards the car) closes ``u T`` meanwhile: the oncoming lane
  must be free of tracks to ``X + u T + margin`` ahead;
- an *unseen* one beyond the LiDAR's confirmed sight (`PassParams.sight`) is judged by the
  road-traffic rule for lanes shared with oncoming traffic: every driver must be able to
  stop within the distance it can see, and where oncoming traffic may be in its lane,
  within half of it (German StVO 3(1); the Vienna Convention, art. 13, asks the same: stop
  within the distance ahead that is clear). So the car's stopping distance at the pass
  speed plus that of a vehicle coming at the posted limit must fit within the sight:
  ``stop(v_p) + stop(v_limit) <= sight``, ``stop(v) = v t_react + v^2 / (2 a_stop)``
  (``t_react`` 1 s, ``a_stop`` 6 m/s^2, a firm but not full stop). Each then stops short of
  the other. With the stack's 55 m this allows passes on roads up to about 45 km/h; at
  50 km/h the two need 60 m. While the car is in the oncoming lane its speed is capped to
  the highest speed at which the rule holds (`speed_cap`).

The centre line must be broken over
the whole pass (a solid line may not be crossed: the map's paint, `world.hdmap.LinePaint`;
a road the map file does not paint has the double solid yellow line of the road's own
rules), and no junction or marked crossing may lie within the pass's travel (plus
``crossing_margin`` before a crossing).

`decide` returns the verdict with the reason the car stays behind (for its state change,
logged once per change of reason by the motion layer), e.g. ``no pass: sight 55 m < 60 m
needed`` or ``no pass: oncoming car 180 m ahead closes in 9.1 s, pass needs 12.0 s``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from planner.limits import SIGHT
from world.hdmap import Crosswalk, MarkKind, RoadMap


@dataclass(frozen=True, slots=True)
class PassParams:
    a_pass: float = 1.5  # [m/s^2] the car speeds up at this to the pass speed
    t_lane: float = 4.0  # [s] the return to the own lane (a lane change's nominal duration)
    t_return: float = 1.0  # [s] the gap ahead of the slow vehicle the car returns into ...
    return_gap: float = 8.0  # [m] ... at least this
    t_margin: float = 2.0  # [s] added to the pass's time
    margin: float = 20.0  # [m] added to the distance that must be free
    min_closing: float = 2.0  # [m/s] a pass needs the car this much faster than the vehicle
    crossing_margin: float = 20.0  # [m] no pass ends within this before a marked crossing
    sight: float = SIGHT  # [m] how far ahead the tracks show a vehicle
    #   (`planner.planner.PlannerParams.sight_range`)
    t_react: float = 1.0  # [s] reaction time of the stopping distance (both drivers)
    a_stop: float = 6.0  # [m/s^2] deceleration of the stopping distance (both drivers)


@dataclass(frozen=True, slots=True)
class Slow:
    """The vehicle to pass, ahead in the car's lane."""

    gap: float  # [m] bumper to bumper
    speed: float  # [m/s] along the route, >= 0
    length: float  # [m] its box's length along the road


@dataclass(frozen=True, slots=True)
class Oncoming:
    """A vehicle ahead in the oncoming lane."""

    gap: float  # [m] the car's front bumper to its front, along the route
    speed: float  # [m/s] towards the car (> 0: coming closer)


@dataclass(frozen=True, slots=True)
class PassPlan:
    """The pass's time and travel (module doc)."""

    time: float  # [s] T
    travel: float  # [m] X, the car's travel over T


@dataclass(frozen=True, slots=True)
class Verdict:
    ok: bool
    reason: str  # why not (empty when ok)


def closing_time(distance: float, v0: float, v_max: float, a: float) -> float:
    """[s] the time to close `distance` [m] at a relative speed starting at `v0` [m/s] and
    rising at `a` [m/s^2] up to `v_max` [m/s] (> 0)."""
    v0 = min(max(v0, 0.0), v_max)
    t_acc = (v_max - v0) / a
    d_acc = v0 * t_acc + 0.5 * a * t_acc * t_acc
    if d_acc >= distance:
        return (-v0 + math.sqrt(v0 * v0 + 2.0 * a * distance)) / a
    return t_acc + (distance - d_acc) / v_max


def stopping_distance(v: float, p: PassParams) -> float:
    """[m] ``v t_react + v^2 / (2 a_stop)`` from `v` [m/s] (module doc)."""
    v = max(v, 0.0)
    return v * p.t_react + v * v / (2.0 * p.a_stop)


def sight_needed(v_pass: float, limit: float, p: PassParams) -> float:
    """[m] the sight a pass at `v_pass` [m/s] needs on a road posted at `limit` [m/s]: the
    car's stopping distance plus that of an unseen oncoming vehicle at the limit."""
    return stopping_distance(v_pass, p) + stopping_distance(limit, p)


def speed_cap(limit: float, p: PassParams) -> float:
    """[m/s] the highest speed whose stopping distance leaves, within the sight, room for
    an oncoming vehicle at `limit` [m/s] to stop (0 when none does): the root of
    ``v t_react + v^2 / (2 a_stop) = sight - stop(limit)``."""
    room = p.sight - stopping_distance(limit, p)
    if room <= 0.0:
        return 0.0
    a, t = p.a_stop, p.t_react
    return -a * t + math.sqrt(a * a * t * t + 2.0 * a * room)


def plan_pass(v: float, v_pass: float, slow: Slow, ego_length: float,
              p: PassParams) -> PassPlan | None:
    """The pass of `slow` by the car at `v` [m/s] speeding up to `v_pass` [m/s]; None when
    the car would not be ``min_closing`` faster than it."""
    if v_pass - slow.speed < p.min_closing:
        return None
    distance = slow.gap + slow.length + ego_length + max(slow.speed * p.t_return, p.return_gap)
    t_rel = closing_time(distance, v - slow.speed, v_pass - slow.speed, p.a_pass)
    t_after = p.t_lane + p.t_margin
    return PassPlan(t_rel + t_after, slow.speed * t_rel + distance + v_pass * t_after)


def decide(road: RoadMap, s_front: float, v: float, v_pass: float, slow: Slow,
           oncoming: Sequence[Oncoming], ego_length: float, p: PassParams) -> Verdict:
    """Whether the car, front bumper at station `s_front` [m], at `v` [m/s], may pass `slow`
    through the oncoming lane now, at up to `v_pass` [m/s] (module doc)."""
    plan = plan_pass(v, v_pass, slow, ego_length, p)
    if plan is None:
        return Verdict(False, f"no pass: the vehicle ahead at {slow.speed * 3.6:.0f} km/h is "
                              f"not slower than the pass speed by {p.min_closing * 3.6:.0f} km/h")
    paint = _paint_reason(road, s_front, s_front + plan.travel, p.crossing_margin)
    if paint:
        return Verdict(False, paint)
    limit = float(road.speed_limit_at(s_front))  # [m/s] an unseen oncoming car's speed
    need = sight_needed(v_pass, limit, p)
    if p.sight < need:
        return Verdict(False, f"no pass: sight {p.sight:.0f} m < {need:.0f} m needed")
    reason = tracks_reason(plan, v_pass, oncoming, p)
    return Verdict(not reason, reason)


def tracks_reason(plan: PassPlan, v_pass: float, oncoming: Sequence[Oncoming],
                  p: PassParams) -> str:
    """Why a tracked oncoming vehicle makes the pass `plan` at up to `v_pass` [m/s] unsafe
    (empty: none does): the nearest one within ``X + u T + margin`` (module doc)."""
    for car in sorted(oncoming, key=lambda c: c.gap):
        u = max(car.speed, 0.0)
        free = plan.travel + u * plan.time + p.margin
        if car.gap < free:
            meet = car.gap / (u + v_pass) if u + v_pass > 0.0 else math.inf
            return (f"no pass: oncoming car {car.gap:.0f} m ahead closes in {meet:.1f} s, "
                    f"pass needs {plan.time:.1f} s")
    return ""


def _paint_reason(road: RoadMap, s0: float, s1: float, crossing_margin: float) -> str:
    """Why the stretch [s0, s1] [m] may not be passed on (empty: it may): a junction, a
    marked crossing within `crossing_margin` [m] past it, a solid centre line."""
    for j in road.junctions:
        if j.s_stop <= s1 and j.s_exit >= s0:
            return "no pass: a junction within the pass"
    for f in road.features:
        if isinstance(f, Crosswalk) and s0 <= f.s + f.width and f.s <= s1 + crossing_margin:
            return "no pass: a marked crossing within the pass"
    step = 5.0  # [m] the centre line is read every this along the pass
    n = max(math.ceil((s1 - s0) / step), 1)
    for k in range(n + 1):
        s = min(s0 + k * step, road.length)
        if centre_line(road, s) is not MarkKind.BROKEN:
            return f"no pass: solid centre line at s = {s:.0f} m"
    return ""


def centre_line(road: RoadMap, s: float) -> MarkKind:
    """How the centre line at station `s` [m] is painted: the map file's paint, else the
    road's own rules (a double solid yellow line); NONE where there is no oncoming lane."""
    section = road.cross_section_at(s)
    if section.oncoming_lanes == 0:
        return MarkKind.NONE
    if section.paint is None:
        return MarkKind.SOLID
    return section.paint.left_edge.kind
