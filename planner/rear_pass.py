"""Whether a pass may start with vehicles coming up behind in the lane it moves into: the
whole pass judged, not only the move out.

UN R157 5.2.6.2's rear rule (`planner.lane_occupancy.is_free`) judges the move out: a
vehicle approaching in the target lane need not brake harder than 3 m/s^2 to stay behind.
A pass is more than that move: out, past the slower vehicle and back in, and a vehicle
behind that keeps its speed (it may not brake for the car at all) must still be a safe gap
behind when the car is back in its own lane. A car 55 m back at 73 km/h satisfies the rule
for the move out of a car at 50 km/h (it would brake at under 1 m/s^2) yet, never braking,
reaches it within the 10 s of a pass behind a standing car.

Stations [m] run along the route, speeds [m/s] along it, times [s] from now. The car, at
speed v, speeds up (or holds) at ``a_pass`` to the pass speed v_p (the speed it wants;
from min(v, v_p): a car faster than v_p is judged at v_p, the slower, the more cautious).
The pass has two phases:

1. out and past: the car gains on the slower vehicle (speed v_s, gap g, length L_s)
   ``g + L_s + L_car + g_back``, where g_back is the gap it keeps behind it on the way
   back (the gaps the planner keeps, `planner.motion_layer`: the rear rule's v_p t_G for a
   vehicle behind in the lane returned into, and keeping right's ``keep_right_gap`` at
   the vehicle's own speed while the car yields to a faster one behind it); this takes
   t_past (`planner.oncoming_pass.closing_time`), and at least t_out, the move out's own
   duration (the way back starts once the move out is done);
2. back: t_back, the lane change back at v_p (`planner.lane_change_path.plan_duration`).

The pass takes ``T = max(t_past, t_out) + t_back``; the car travels X(T) in it. A vehicle
behind in the target lane at gap g_r and speed u, not braking, is then
``g_r + X(T) - u T`` behind; the pass may start only if that is at least UN R157's rear
distance at its speed (the gap at which it would need to brake at ``rear_decel`` after
``rear_reaction`` to stay ``rear_time_gap`` behind the car at the speed it has then):

    g_r + X(T) - u T >= dv t_B + dv^2 / (2 a_rear) + v_T t_G,   dv = max(u - v_T, 0).

Every vehicle behind in the target lane is judged, not only the nearest: a farther one may
be faster. A vehicle slower than the car only falls back; one standing or going the other
way never comes up. Vehicles beyond the tracks' reach behind are not judged here (the rear
rule of the move out, with its sight, is the rule for those).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from planner.lane_occupancy import Neighbour, OccupancyParams
from planner.oncoming_pass import closing_time


@dataclass(frozen=True, slots=True)
class RearPassParams:
    a_pass: float = 1.5  # [m/s^2] the car speeds up at this to the pass speed
    #   (`planner.oncoming_pass.PassParams.a_pass`)
    keep_right_gap: float = 2.0  # [s] keeping right waits for a vehicle just passed to be
    #   this far back at its own speed (`planner.motion_layer.MotionLayerParams`)


@dataclass(frozen=True, slots=True)
class Pass:
    """A pass of a slower vehicle, as the planner would drive it (module doc)."""

    v: float  # [m/s] the car's speed now
    v_pass: float  # [m/s] the speed it wants on the pass
    slow: Neighbour  # the vehicle to pass, ahead in the lane kept
    car_length: float  # [m] the car's length
    t_out: float  # [s] the move out's duration
    t_back: float  # [s] the move back's duration, at `v_pass`


def travel(t: float, v0: float, v_max: float, a: float) -> float:
    """[m] the distance covered in `t` [s] from `v0` [m/s] speeding up at `a` [m/s^2] to
    `v_max` [m/s] (`v0` above it: from `v_max`)."""
    v0 = min(max(v0, 0.0), v_max)
    t_acc = min((v_max - v0) / a, max(t, 0.0))
    return v0 * t_acc + 0.5 * a * t_acc * t_acc + v_max * max(t - t_acc, 0.0)


def pass_time(ps: Pass, occ: OccupancyParams, p: RearPassParams) -> float | None:
    """[s] T, the pass's time until the car is back in its lane (module doc); None when the
    car at `v_pass` would never get past the slower vehicle."""
    v_s = max(ps.slow.speed, 0.0)
    if ps.v_pass <= v_s:
        return None
    back_gap = max(ps.v_pass * occ.rear_time_gap, v_s * p.keep_right_gap)
    distance = max(ps.slow.gap, 0.0) + ps.slow.length + ps.car_length + back_gap
    t_past = closing_time(distance, ps.v - v_s, ps.v_pass - v_s, p.a_pass)
    return max(t_past, ps.t_out) + ps.t_back


def rear_gap_needed(u: float, v: float, occ: OccupancyParams) -> float:
    """[m] UN R157's rear distance: the least gap behind the car at `v` [m/s] at which a
    vehicle at `u` [m/s] need not brake harder than ``rear_decel`` after ``rear_reaction``
    to stay ``rear_time_gap`` behind it (`planner.lane_occupancy.rear_decel_needed`)."""
    dv = max(u - v, 0.0)
    return dv * occ.rear_reaction + dv * dv / (2.0 * occ.rear_decel) + v * occ.rear_time_gap


def gap_after(n: Neighbour, t: float, ps: Pass, p: RearPassParams) -> float:
    """[m] the gap of vehicle `n` behind, at its speed, to the car `t` [s] into the pass."""
    return n.gap + travel(t, ps.v, ps.v_pass, p.a_pass) - max(n.speed, 0.0) * t


def rear_catches(ps: Pass, behind: Sequence[Neighbour], occ: OccupancyParams,
                 p: RearPassParams) -> Neighbour | None:
    """The first (nearest) vehicle of `behind` in the target lane that, keeping its speed,
    is nearer than the rear distance when the car is back in its lane (module doc); None
    when every one is far enough back, and the pass may start. A pass that never gets past
    the slower vehicle is caught by the nearest vehicle behind that moves."""
    t = pass_time(ps, occ, p)
    v_end = ps.v_pass if t is None else min(max(ps.v, 0.0) + p.a_pass * t, ps.v_pass)
    for n in sorted(behind, key=lambda b: b.gap):
        if n.speed <= 0.0:
            continue
        if t is None or gap_after(n, t, ps, p) < rear_gap_needed(n.speed, v_end, occ):
            return n
    return None
