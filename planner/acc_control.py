"""The laws of the ACC / event modes: a speed reference [m/s] and a feed-forward acceleration
[m/s^2] for the speed loop (`control.longitudinal`), one law per mode.

The DECS paper names them (hard braking, speed limit, off-ramp, speed bump) but its
equations are missing; these are designed here (parameters `AccControlParams`). Distances
are metres along the route, speeds m/s; v is the ego speed, v_l the lead's, d the bumper gap
to it, v_plan the speed plan's reference (`planner.speed_planning`, after the driver's
pedal). `planner.acc_layer` picks the law for the mode.

- CRUISE, SPEED_LIMIT, OFF_RAMP: the speed plan itself (the set speed, the posted limit
  V_GPS at the front bumper and the curves, with braking curves at a_comf towards lower
  limits ahead). An exit ramp's limit is a posting of the map.
- TRAIL, constant time-gap following (`trail`): ``v_ref = min(v_l + k_gap (d - d_des),
  sqrt(v_l^2 + 2 a_comf max(d - d0, 0)))``, clamped to [0, v_plan], no feed-forward. The
  first term feeds the lead's speed forward and closes the gap error with the time constant
  1 / k_gap, slow enough not to chase the lead's speed noise; the second is the speed from
  which braking at a_comf still stops d0 behind a lead that stops. Stop-and-go: behind a
  lead slower than ``v_standstill`` the gap law would creep up on it for several of its time
  constants, so the reference is the braking curve ``sqrt(2 a_final max(d - d0 - stop_band,
  0))`` alone: the car comes to rest ``stop_band`` beyond d0 in finite time, the speed loop
  holds it, and it moves off as soon as the lead does.
- BRAKE (gap at or below d_min), hard braking that eases in: the deceleration that brings
  the speed down to the trail law's v_trail (below the lead's while the gap is short, so the
  gap opens again) before the gap shrinks to d_stop, ``a_need = max(v^2 - v_trail^2, 0) /
  (2 max(d - d_stop, 0.5 m))`` (`braking_need`), at most a_firm (enough for a cut-in at UN
  R157's distances), or a_hard when the time to collision ``d / (v - v_l)`` is under
  ``ttc_hard`` (`brake_cap`). The command rises towards it at no more than the jerk j_in
  ("the throttle is held momentarily, then gradually eased"), so a cut-in does not jolt the
  car (or the one behind it), and drops at once when less is needed (`EasedBrake`). The
  speed reference follows the planned deceleration, ``v - a_cmd dt``, so that the speed loop
  adds little of its own.
- PEDESTRIAN, STOP_SIGN, RED_LIGHT, YIELD: stop ``margin`` before a point ``s_stop`` ahead
  of the front bumper (`stop_speed`): ``v_ref = sqrt(2 a_comf (s_stop - margin))``, and 0
  once ``s_stop - margin <= arrived``. The cut-off is there because the speed loop cannot
  follow the curve's vertical end: the car comes to rest a little short, where the curve
  still asks for a speed the drive cannot break away at, and the speed loop's integrator
  would wind up for as long as the car waits and overshoot when it moves off.
- SPEED_BUMP: cross at the bump's pass speed v_pass (`pass_speed`): ``v_ref = sqrt(v_pass^2
  + 2 a_comf max(d_bump - margin, 0))``, d_bump the front axle's distance to the point where
  it must be at v_pass (`planner.events`).
- FLAT: the reference falls at ``a_flat_plan`` (gentler than the DECS bound a_flat) from
  the plan's speed at the tick FLAT is entered, never above the car's own speed, down to a
  crawl, ``v_pull_over`` (or the plan's speed if lower), while the motion FSM pulls the car
  onto the shoulder, then to a stop there; the speed loop's jerk limit eases it in.

TRAIL, the stops and the bump end in ``min(v_ref, v_plan)``, and BRAKE gives way to the plan
where the plan is lower (`planner.acc_layer`): no mode but FLAT plans faster than the map
allows. FLAT's ramp starts from the plan's speed and then falls without looking at it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from planner.limits import A_COMF, A_FIRM, A_FLAT, A_HARD
from planner.speed import SpeedRef


@dataclass(frozen=True, slots=True)
class AccControlParams:
    k_gap: float = 0.25  # [1/s] trail: gap error to speed (1 / the gap's time constant)
    a_comf: float = A_COMF  # [m/s^2] comfortable deceleration (stops, bumps)
    a_firm: float = A_FIRM  # [m/s^2] the most BRAKE plans unless a collision is imminent
    a_hard: float = A_HARD  # [m/s^2] the most BRAKE plans when it is
    ttc_hard: float = 2.5  # [s] time to collision below which a_hard is allowed
    a_flat: float = A_FLAT  # [m/s^2] DECS's bound on FLAT's deceleration (no law reads it)
    a_flat_plan: float = 2.0  # [m/s^2] the deceleration FLAT plans: a gentle stop
    v_pull_over: float = 6.0  # [m/s] FLAT's crawl while the car pulls onto the shoulder (slow
    #   enough to stop short, quick enough to cross onto it within the 8 s a lane change has)
    j_in: float = 4.0  # [m/s^3] how fast BRAKE's deceleration eases in
    d_stop: float = 2.0  # [m] gap BRAKE aims to keep at the lead's speed
    margin: float = 1.0  # [m] stop / pass points are aimed this far before the point
    arrived: float = 0.3  # [m] this near its stop point, a car stopping has arrived
    v_standstill: float = 0.5  # [m/s] a lead slower than this counts as stopped (trail)
    stop_band: float = 1.0  # [m] behind a stopped lead, stop this far beyond d0 (trail)
    a_final: float = 0.5  # [m/s^2] the last metres' deceleration behind a stopped lead


def trail(v_plan: float, d: float, d_des: float, v_l: float, d0: float,
          p: AccControlParams) -> SpeedRef:
    """TRAIL's law (module doc): the reference behind a lead at bumper gap d [m] with speed
    v_l [m/s], for the desired gap d_des and standstill gap d0 [m], at most v_plan [m/s]."""
    if v_l < p.v_standstill:
        approach = math.sqrt(2.0 * p.a_final * max(d - d0 - p.stop_band, 0.0))
        return SpeedRef(min(approach, v_plan), 0.0)
    gap_law = v_l + p.k_gap * (d - d_des)
    stop_law = math.sqrt(max(v_l, 0.0) ** 2 + 2.0 * p.a_comf * max(d - d0, 0.0))
    return SpeedRef(min(max(min(gap_law, stop_law), 0.0), v_plan), 0.0)


def braking_need(v: float, v_l: float, d: float, p: AccControlParams) -> float:
    """[m/s^2] >= 0: the deceleration that slows from v to v_l [m/s] before the gap d [m]
    shrinks to d_stop, at most a_hard."""
    room = max(d - p.d_stop, 0.5)
    return min(max(v * v - max(v_l, 0.0) ** 2, 0.0) / (2.0 * room), p.a_hard)


def brake_cap(v: float, v_lead: float, d: float, p: AccControlParams) -> float:
    """[m/s^2] the most BRAKE may plan: a_firm, or a_hard when the time to collision at the
    present closing speed v - v_lead is under ttc_hard."""
    closing = v - v_lead
    return p.a_hard if closing > 0.0 and d / closing < p.ttc_hard else p.a_firm


def stop_speed(distance: float, v_plan: float, p: AccControlParams) -> float:
    """[m/s] the speed from which braking at a_comf stops `margin` before `distance` [m],
    at most v_plan [m/s]; 0 within `arrived` of that point (or past it)."""
    left = distance - p.margin
    return min(math.sqrt(2.0 * p.a_comf * left), v_plan) if left > p.arrived else 0.0


def pass_speed(distance: float, v_pass: float, v_plan: float, p: AccControlParams) -> float:
    """[m/s] the speed from which braking at a_comf reaches v_pass [m/s] `margin` before
    `distance` [m], at most v_plan [m/s]."""
    return min(math.sqrt(v_pass**2 + 2.0 * p.a_comf * max(distance - p.margin, 0.0)), v_plan)


class EasedBrake:
    """A deceleration command that rises at most at the jerk j_in and falls at once."""

    def __init__(self) -> None:
        self.a = 0.0  # [m/s^2] >= 0, the deceleration commanded last

    def reset(self) -> None:
        self.a = 0.0

    def step(self, v: float, a_need: float, dt: float, p: AccControlParams,
             cap: float | None = None) -> SpeedRef:
        """Move the command towards `a_need` (capped at `cap`, default a_hard) and give the
        speed reference that follows it from the current speed v over dt [s]."""
        target = min(a_need, p.a_hard if cap is None else cap)
        self.a = min(target, self.a + p.j_in * dt)
        return SpeedRef(max(v - self.a * dt, 0.0), -self.a)
