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
  sqrt(v_l^2 + 2 a_comf max(d - d0, 0)))``, clamped to [0, v_plan]. The first term feeds
  the lead's speed forward and closes the gap error with the time constant 1 / k_gap, slow
  enough not to chase the lead's speed noise; the second is the speed from which braking at
  a_comf still stops d0 behind a lead that stops. While the lead brakes gently (b up to
  a_gentle), the car following it brakes as it does and d_des shrinks with the car's speed
  at d_des'(v) b: the first term gets ``+ d_des'(v) b`` (tapering to 0 at 2 a_gentle: a lead
  braking harder is not closed in on), else the gap error alone lags the shrinking d_des by
  d_des' b / k_gap (ISO 22179 stop and go, a lead stopping at 1 m/s^2 from 40 km/h: 13 m
  behind at 2 m/s when it stopped, and the car crept its last 8 m at a_final and never
  stood before it drove off again; now it stands 4.8 m behind). Where the first binds and
  the lead brakes (its acceleration from its track, `planner.lead.LeadAccel`, under
  -`lead_brakes`), its deceleration is the feed-forward, and its speed is taken less what
  it shed since its track's measurement and over the track's lag (`lead_speed_now`, every
  law and the mode's inputs): without it the reference fell with the lead's speed and the speed loop
  followed tau_loop behind, and a car following at 90 km/h behind a lead braking at
  2 m/s^2 fell 2 m under UN R157's d_min. Where the first binds and the lead
  pulls away (its acceleration a_l over `lead_brakes`), its acceleration up to `a_pull` is
  the feed-forward, less k_gap (v - v_l) while the car closes on it (the law's own rate;
  fed in full, a car closing from far behind sped up through the law's reference and past
  the plan's): the gap law's reference rises with the lead's speed, and without it the
  speed loop's integrator takes up the pull-away (0.9 m/s^2 behind a lead pulling away at
  1 m/s^2) and holds it against the braking that follows when the lead brakes again at
  once (ISO 22179 stop and go): the car brakes that much less than its plan. And as
  while the lead brakes, d_des grows with the car's speed at d_des'(v) a_l: the first term
  gets ``- d_des'(v) a_l`` (`gap_rate`), else the gap lags the growing d_des by d_des' a_l /
  k_gap and UN R157's d_min, which grows faster still (1 s + 2 v / 100 km/h s of speed),
  catches it up in a brisk pull-away (2.5 m/s^2 to 40 km/h: under d_min at 35 km/h). Stop-and-go:
  behind a lead slower than ``v_standstill`` the gap law would creep up on it for several
  of its time constants, so the reference is the braking curve ``sqrt(2 a_final max(d - d0
  - stop_band, 0))`` alone: the car comes to rest ``stop_band`` beyond d0 in finite time (a
  bumper gap of d0 + stop_band = 5 m, inside UN R157 4.2.1's 2 to 6 m), the speed loop
  holds it, and it moves off as soon as the lead does.
- The d_min guard (`guard_decel`, every law behind a lead, through `follow`). The gap law
  closes its error slowly (1 / k_gap = 4 s) and its shrink term assumes the car is at
  d_des: behind a lead that brakes again soon after pulling away, the car still well inside
  d_des and faster than the lead, the approach planned the stop behind where the lead would
  rest (under 1 m/s^2), the car kept closing and the gap fell under UN R157's d_min at
  15 km/h. So while the car closes on the lead below v_guard, its deceleration is at least
  ``b + (v - v_l)^2 / (2 (d - d_min(v) - d_keep))`` (b the lead's braking, d_min at the
  car's speed, `planner.fsm.acc.r157_min_gap`), which ends the closing d_keep above d_min;
  d_min falls as the car slows, so the bound is on the safe side. It holds in full within
  d_near (2 m) of d_min and tapers to nothing at d_far (3 m), so following further out is
  the laws' alone. Above v_guard, d_min(v) - d_min(v_l) is large (1 + 2 v / 100 km/h s of
  speed: 13 m at 55 km/h behind a lead at 30 km/h) and that bound would brake hard for any
  closing at d_min; there the guard is `restore_decel`: at least ``(v - v_l) / d_min'(v)``,
  at which the margin d - d_min(v) stops falling (it rises after: the closing falls faster
  than d_min'(v) does), and at least ``(v - v_l)^2 / (2 (d - d_min(v_l) - d_keep))``, which
  ends the closing d_keep above d_min at the lead's speed (no room: +inf). Steady following
  there never meets it (d_des is 3.2 m or more above d_min above v_guard, beyond d_far); a
  lead first found near or under d_min with a closing speed does (a slower car found 24 m
  ahead at 55 km/h, 30 km/h slower: the comfortable plan to d_des and, inside d_des, the stop
  of the closing at d_floor let the gap fall to 7 m, d_min being 16 m). What the guard asks
  is `need` too for the approach's cap (`follow`): over a_comf_max it is planned within
  ISO's limits, and over a_iso_max at a_hard, with the speed loop's comfort envelope off.
- The approach (`approach`, every law behind a lead and every stop or pass point; ISO 15622
  / ISO 22179 comfort: at most 3.5 m/s^2 over 2 s, its rise at most 2.5 m/s^3 over 1 s). A
  speed law's reference below the car's speed would make the speed loop brake at ``(v -
  v_ref) / tau_loop`` at once: a car that meets a slower lead, a stopped car revealed by a
  cut-out or a stop line in its law's reach faster than the law's curve would be jolted.
  Where the car is faster than the law, the reference is instead a planned constant
  deceleration, the one that brings the closing speed to zero at the law's end point,
  ``a_plan = (v^2 - v_end^2) / (2 room)`` (a stop or pass point; behind a lead ``(v - v_l)^2
  / (2 (d - d_end))``, d_end = d_des(v_l) or, behind a stopped lead, d0 + stop_band; behind
  a lead braking at b, ``b + (v - v_l)^2 / (2 (d - d_end))`` if that ends the closing before
  the lead comes to rest, else the stop d0 + stop_band behind where it rests, ``v^2 / (2 (d
  + v_l^2 / (2 b) - d0 - stop_band))``: `closing_plan`; a plan that takes the lead's speed
  now for its speed to come braked at 1 m/s^2 behind a lead braking at 2),
  whenever it is gentler than the speed loop's reaction and that reaction exceeds a_gentle
  (1 m/s^2: below it the law itself acts, so a lead that slows down is followed as it slows,
  not by a plan that assumes its speed now); the reference then follows it from the car's
  speed (``v - a dt``, feed-forward -a) and the speed loop's jerk limit
  (`control.longitudinal`: comfort_jerk) eases it in. It is never gentler than ``need``, the
  least deceleration that still stops the closing at d_floor (2.5 m: UN R157 4.2.1's least
  standstill gap of 2 m and a margin; once the car is inside d_end, it keeps to the law, or,
  where the law would brake harder than a_open, stops the closing at the floor at a_open or
  more), the room shortened by the closing speed times ``t_ramp = (a_comf_max - a_now)^2 /
  (2 j_comf a_comf_max)``, what the ramp-in at the speed loop's comfort jerk from the
  deceleration the car already brakes at (a_now, `BrakeModel`) to a_comf_max costs against
  braking at a_comf_max at once (to first order in the ramp's time T = (a_comf_max - a_now) /
  j_comf: the car loses ``(v - v_l) T / 2`` of room to the ramp and gains ``(v - v_l) T a_now
  / (2 a_comf_max)`` back from braking already; the terms in T^2 shorten the stop, so the
  room left out is on the safe side): ``need = (v - v_l)^2 / (2 (d - d_floor - (v - v_l)
  t_ramp))``, and behind a lead braking at b at least the stop d_floor behind where it will
  rest, ``v^2 / (2 (d - d_floor + v_l^2 / (2 b) - v t_ramp))``. Without the gain, the
  need of a car that ramps in as planned rose by a twentieth during the ramp (a stopped
  car found 63 m ahead at 60 km/h: 2.85 to 3.03 m/s^2, over a_comf_max: BRAKE, comfort
  envelope off). The planned deceleration is
  capped at a_comf_max (`planner.limits.A_COMF_MAX`, under ISO's 3.5 m/s^2), so that a car
  short of room stops a little nearer rather than harder; only when even ``need`` exceeds
  a_comf_max is there no comfortable stop: the ACC enters BRAKE saying so (`planner.fsm.acc`:
  "no comfortable stop: needs 3.9 m/s^2, ttc 2.1 s"; the time to collision is reported, not
  judged: a planned stop behind a stopped car ends with a short one) and the cap is a_iso,
  or ``need`` itself up to a_iso_max, while ``need`` is within a_iso_max
  (`planner.limits.A_ISO_PLAN`, `A_ISO_MAX`: a stop within ISO's own limits is left, and the
  speed loop builds it at ISO's jerk; the cap follows ``need`` past a_iso, so that a need
  that wavers about a_iso does not flick the plan to a_hard and back, a jerk of 8 m/s^3;
  a stopped car revealed by a cut-out 50 m ahead at 60 km/h needs 3.1 m/s^2, and braking
  at up to a_hard with the envelope off rose at 3.4 m/s^3), else a_hard, the feed-forward
  beyond a_iso_max telling the speed loop the plan is urgent. The stops and the bump use
  the same approach with room = the distance to their point less the margin and the ramp-in
  from the deceleration the car brakes at (`ramped`; need = a_plan: a point on the map has
  no floor short of it). Of the laws that bind (the speed plan, an event's, the trail
  law behind a vehicle ahead), the one the speed loop would ask least of the car on is taken,
  the minimum of the laws' outputs (`planner.acc_layer`).
- BRAKE (gap at or below d_min, or no comfortable stop): the approach behind the lead on
  the trail law, with the gap opened at no more than ``a_open`` while it is under d_min
  and the lead is not closing, and the cap a_comf_max, or a_iso or a_hard when no
  comfortable stop is left (as above). Harder still is the control FSM's emergency stop.
- PEDESTRIAN, STOP_SIGN, RED_LIGHT, YIELD: stop ``margin`` before a point ``s_stop`` ahead
  of the front bumper (`stop_speed`): ``v_ref = sqrt(2 a_comf (s_stop - margin))``, and 0
  once ``s_stop - margin <= arrived``, through the approach (`stop`). The cut-off is
  there because the speed loop cannot follow the curve's vertical end: the car comes to
  rest a little short, where the curve still asks for a speed the drive cannot break away
  at, and the speed loop's integrator would wind up for as long as the car waits and
  overshoot when it moves off.
- SPEED_BUMP: cross at the bump's pass speed v_pass (`pass_speed`): ``v_ref = sqrt(v_pass^2
  + 2 a_comf max(d_bump - margin, 0))``, d_bump the front axle's distance to the point where
  it must be at v_pass (`planner.events`), through the approach.
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

from planner.fsm.acc import r157_min_gap
from planner.limits import (
    A_COMF,
    A_COMF_MAX,
    A_FLAT,
    A_HARD,
    A_ISO_MAX,
    A_ISO_PLAN,
    J_COMF,
    J_ISO_PLAN,
)
from planner.speed import SpeedRef
from world.frames import to_kph


@dataclass(frozen=True, slots=True)
class AccControlParams:
    k_gap: float = 0.25  # [1/s] trail: gap error to speed (1 / the gap's time constant)
    a_comf: float = A_COMF  # [m/s^2] comfortable deceleration (stops, bumps)
    a_comf_max: float = A_COMF_MAX  # [m/s^2] the most a comfortable approach plans
    a_iso: float = A_ISO_PLAN  # [m/s^2] BRAKE plans at most this, or `need` up to a_iso_max,
    a_iso_max: float = A_ISO_MAX  # when no comfortable stop is left but one within ISO's
    #   limits is
    a_hard: float = A_HARD  # [m/s^2] the most BRAKE plans when no stop within ISO's is left
    a_open: float = A_COMF  # [m/s^2] BRAKE opens a gap under d_min at no more than this
    a_gentle: float = 1.0  # [m/s^2] the approach keeps to the law while the speed loop's
    #   reaction to it is no harder than this (a lead slowing down is followed as it slows)
    tau_loop: float = 0.8  # [s] the speed loop's time constant (`control.longitudinal`):
    #   it brakes at (v - v_ref) / tau_loop on a reference below the speed
    j_iso: float = J_ISO_PLAN  # [m/s^3] the speed loop builds a plan within ISO's limits at
    #   this (`restore_decel`: the ramp-in that costs)
    j_comf: float = J_COMF  # [m/s^3] the speed loop eases a comfortable plan in at this
    #   (`control.longitudinal`: comfort_jerk): the ramp-in `need` allows for
    d_floor: float = 2.5  # [m] `need` stops the closing this far behind the lead (UN R157
    #   4.2.1's least standstill gap, 2 m, and a margin)
    d_floor_iso: float = 2.0  # [m] ... and its last resort before an urgent plan, on ISO's
    #   envelope (`follow_need`): UN R157 4.2.1's 2 m
    a_flat: float = A_FLAT  # [m/s^2] DECS's bound on FLAT's deceleration (no law reads it)
    a_flat_plan: float = 2.0  # [m/s^2] the deceleration FLAT plans: a gentle stop
    v_pull_over: float = 6.0  # [m/s] FLAT's crawl while the car pulls onto the shoulder (slow
    #   enough to stop short, quick enough to cross onto it within the 8 s a lane change has)
    margin: float = 1.0  # [m] stop / pass points are aimed this far before the point
    arrived: float = 0.3  # [m] this near its stop point, a car stopping has arrived
    v_standstill: float = 0.5  # [m/s] a lead slower than this counts as stopped (trail)
    stop_band: float = 1.0  # [m] behind a stopped lead, stop this far beyond d0 (trail)
    a_final: float = 0.5  # [m/s^2] the last metres' deceleration behind a stopped lead
    lead_brakes: float = 0.5  # [m/s^2] a lead decelerating more brakes (`lead_braking`)
    a_pull: float = 2.0  # [m/s^2] the most of a lead's pull-away the trail law feeds forward
    #   (ISO 15622's most an ACC accelerates above 20 m/s, 2 s average)
    track_lag: float = 0.4  # [s] a lead's track speed lags its true speed by about this
    #   while it brakes (`perception.tracking`'s constant-velocity filter: 1.7 m/s behind a
    #   car braking at 4 m/s^2, measured; `lead_speed_now`)
    v_guard: float = 10.0  # [m/s] up to this speed `guard_decel` ends the closing above
    #   d_min at the car's speed now; above it, above d_min at the lead's (`restore_decel`)
    d_keep: float = 0.75  # [m] `guard_decel` ends the closing this far above d_min
    d_lose: float = 1.0  # [m] `restore_decel` holds d_min at up to a_hard until the gap is
    #   this far under d_min + d_keep (a hard braking's ramp-in may lose that much); further
    #   under (a cut-in), the guard steps aside
    d_near: float = 2.0  # [m] `guard_decel` holds in full within this of d_min ...
    d_far: float = 3.0  # [m] ... tapering to nothing this far above it


def lead_braking(a_lead: float, p: AccControlParams) -> float:
    """[m/s^2] >= 0: the lead's deceleration, from its signed acceleration `a_lead` [m/s^2]
    (`planner.lead.LeadAccel`); 0 unless it brakes harder than `lead_brakes` (the estimate's
    noise while it holds its speed)."""
    return -a_lead if a_lead < -p.lead_brakes else 0.0


def lead_feed_forward(a_lead: float, p: AccControlParams) -> float:
    """[m/s^2] (signed) the trail law's feed-forward from the lead's acceleration `a_lead`
    [m/s^2]: its braking (`lead_braking`), or its pull-away's acceleration, when harder than
    `lead_brakes` (the estimate's noise), up to `a_pull`; 0 in between."""
    if a_lead > p.lead_brakes:
        return min(a_lead, p.a_pull)
    return -lead_braking(a_lead, p)


def lead_speed_now(v_l: float, a_lead: float, age: float, p: AccControlParams) -> float:
    """[m/s] the speed of a lead whose track gives v_l [m/s], `age` [s] old, and the
    acceleration `a_lead` [m/s^2] (signed): while it brakes (`lead_braking`), less what it
    shed over the age and the track's lag (`track_lag`), at least 0."""
    return max(v_l - lead_braking(a_lead, p) * (age + p.track_lag), 0.0)


def trail(v_plan: float, d: float, d_des: float, v_l: float, d0: float,
          p: AccControlParams, a_lead: float = 0.0, d_des_slope: float = 0.0,
          closing: float = 0.0) -> SpeedRef:
    """TRAIL's law (module doc): the reference behind a lead at bumper gap d [m] with speed
    v_l [m/s] and acceleration `a_lead` [m/s^2] (signed), for the desired gap d_des and
    standstill gap d0 [m], at most v_plan [m/s]; `d_des_slope` [s] is d(d_des)/dv at the
    car's speed (the gap law's shrink term); `closing` [m/s] the car's speed less the
    lead's (the pull-away's feed-forward is the law's own rate while it closes)."""
    if v_l < p.v_standstill:
        approach = math.sqrt(2.0 * p.a_final * max(d - d0 - p.stop_band, 0.0))
        return SpeedRef(min(approach, v_plan), 0.0)
    gap_law = v_l - d_des_slope * gap_rate(a_lead, p) + p.k_gap * (d - d_des)
    stop_law = math.sqrt(max(v_l, 0.0) ** 2 + 2.0 * p.a_comf * max(d - d0, 0.0))
    speed = min(max(min(gap_law, stop_law), 0.0), v_plan)
    feed = lead_feed_forward(a_lead, p)
    if feed > 0.0:  # the gap law's rate, a_l - k_gap (v - v_l), while the car closes
        feed = max(feed - p.k_gap * max(closing, 0.0), 0.0)
    return SpeedRef(speed, feed if 0.0 < speed == gap_law else 0.0)


def gap_rate(a_lead: float, p: AccControlParams) -> float:
    """[m/s^2] (signed) the acceleration the car following the lead is taken to share
    with it for d_des's rate, d_des'(v) times this: its pull-away's feed-forward
    (`lead_feed_forward`), or its braking up to a_gentle, tapering to 0 at 2 a_gentle (a
    lead braking harder is not closed in on)."""
    b = lead_braking(a_lead, p)
    if b > 0.0:
        return -(b if b <= p.a_gentle else max(2.0 * p.a_gentle - b, 0.0))
    return lead_feed_forward(a_lead, p)


def guard_decel(v: float, v_l: float, d: float, a_lead: float, p: AccControlParams,
                entered: bool = False) -> float:
    """[m/s^2] >= 0: the constant deceleration that ends the closing speed v - v_l [m/s] on
    a lead braking at `lead_braking(a_lead)` before the gap d [m] falls to UN R157's d_min
    at the car's speed now plus d_keep (d_min falls as the car slows: the bound is on the
    safe side), ``b + (v - v_l)^2 / (2 (d - d_min(v) - d_keep))``, +inf with no room;
    faster than v_guard, ``b + restore_decel``; `b` alone for a lead that `entered` the
    lane ahead at any speed (UN R157 gives a cut-in time to restore d_min: its closing is
    the approach's); in full within d_near of d_min, tapering linearly to 0 at d_far above
    it; 0 when not closing (module doc). Behind a lead at rest (under v_standstill) UN R157's
    following distance, which is for a moving lead, and the lead's braking (its estimate
    still says so as it comes to rest) no longer apply: the stop d_keep behind R157's
    standstill gap, ``(v - v_l)^2 / (2 (d - d_min(0) - d_keep))``, with the same weight."""
    closing = v - max(v_l, 0.0)
    if closing <= 0.0:
        return 0.0
    above = d - r157_min_gap(v)
    weight = min(max((p.d_far - above) / (p.d_far - p.d_near), 0.0), 1.0)
    if weight <= 0.0:
        return 0.0
    if v_l < p.v_standstill:  # a lead at rest: no following distance, no braking to come
        room = d - r157_min_gap(0.0) - p.d_keep
        return weight * closing * closing / (2.0 * room) if room > 0.0 else math.inf
    b = lead_braking(a_lead, p)
    if entered:  # a lead that entered the lane ahead: UN R157's cut-in grace
        return weight * b
    if v > p.v_guard:
        return weight * (b + restore_decel(v, v_l, d, p))
    room = above - p.d_keep
    return weight * (b + closing * closing / (2.0 * room)) if room > 0.0 else math.inf


def d_min_slope(v: float) -> float:
    """[s] d(d_min)/dv, UN R157's d_min (`planner.fsm.acc.r157_min_gap`) at ego speed v
    [m/s]: 1 + 2 v / (100 km/h) where its time gap grows with the speed (above 10 km/h),
    else the constant time gap 1.1 s (d_min's floor of 2 m: 0)."""
    if r157_min_gap(v) <= 2.0:
        return 0.0
    kph = to_kph(v)
    return 1.0 + 2.0 * kph / 100.0 if kph > 10.0 else 1.1


def restore_decel(v: float, v_l: float, d: float, p: AccControlParams) -> float:
    """[m/s^2] >= 0: the deceleration that holds the margin d - d_min(v) [m] to UN R157's
    d_min at the car's speed v [m/s] from falling while it closes on a lead at v_l [m/s],
    ``(v - v_l) / d_min'(v)`` (at a constant deceleration the margin is convex in time: it
    rises from there on), and that ends the closing d_keep above d_min at the lead's speed,
    ``(v - v_l)^2 / (2 (d - d_min(v_l) - d_keep))`` (+inf with no room); +inf where the
    ramp-in to the first at j_iso, which loses about (v - v_l) T / 2 of the margin (T the
    ramp's time), leaves less than d_keep of it (answered at a_hard, `follow`); 0 when not
    closing. More than d_lose under d_min + d_keep already (a cut-in close ahead) no margin
    is left to keep (UN R157 gives a cut-in time to restore d_min): 0, the guard steps
    aside and `need` and the approach end the closing within ISO's limits where they can."""
    closing = v - max(v_l, 0.0)
    if closing <= 0.0:
        return 0.0
    slope = d_min_slope(v)
    hold = closing / slope if slope > 0.0 else 0.0
    margin = d - r157_min_gap(v) - p.d_keep
    if margin < -p.d_lose:  # well under d_min already (doc)
        return 0.0
    if closing * hold / (2.0 * p.j_iso) > margin:
        return math.inf  # the ramp-in to `hold` at ISO's jerk would take the margin
    room = d - r157_min_gap(max(v_l, 0.0)) - p.d_keep
    return max(hold, closing * closing / (2.0 * room) if room > 0.0 else math.inf)


def stop_speed(distance: float, v_plan: float, p: AccControlParams) -> float:
    """[m/s] the speed from which braking at a_comf stops `margin` before `distance` [m],
    at most v_plan [m/s]; 0 within `arrived` of that point (or past it)."""
    left = distance - p.margin
    return min(math.sqrt(2.0 * p.a_comf * left), v_plan) if left > p.arrived else 0.0


def pass_speed(distance: float, v_pass: float, v_plan: float, p: AccControlParams) -> float:
    """[m/s] the speed from which braking at a_comf reaches v_pass [m/s] `margin` before
    `distance` [m], at most v_plan [m/s]."""
    return min(math.sqrt(v_pass**2 + 2.0 * p.a_comf * max(distance - p.margin, 0.0)), v_plan)


def need(v: float, v_l: float, d: float, p: AccControlParams, a_now: float = 0.0,
         a_lead: float = 0.0, iso: bool = False) -> float:
    """[m/s^2] >= 0: the least deceleration that still stops the closing speed v - v_l [m/s]
    at d_floor (module doc) from the gap d [m], after the ramp-in from the deceleration
    `a_now` [m/s^2] the car brakes at (`BrakeModel`; to a_comf_max at j_comf, or with `iso`
    to a_iso_max at j_iso, the envelope of a plan within ISO's limits, stopping d_floor_iso
    short), and, while the lead
    brakes (`lead_braking` of its acceleration `a_lead` [m/s^2]), that stops the car d_floor
    behind where the lead will stop; +inf with no room left."""
    closing = v - max(v_l, 0.0)
    top, jerk = (p.a_iso_max, p.j_iso) if iso else (p.a_comf_max, p.j_comf)
    floor = p.d_floor_iso if iso else p.d_floor
    t_ramp = max(top - a_now, 0.0) ** 2 / (2.0 * jerk * top)
    a = 0.0
    if closing > 0.0:
        room = d - floor - closing * t_ramp
        a = closing * closing / (2.0 * room) if room > 0.0 else math.inf
    b = lead_braking(a_lead, p)
    if b > 0.0:
        room = d - floor + max(v_l, 0.0) ** 2 / (2.0 * b) - v * t_ramp
        a = max(a, v * v / (2.0 * room) if room > 0.0 else math.inf)
    return a


def closing_plan(v: float, v_l: float, b: float, room: float, rest_room: float) -> float:
    """[m/s^2] the constant deceleration that ends the closing on a lead at speed v_l [m/s]
    that brakes at b [m/s^2] (>= 0) within `room` [m] of gap, or, where the lead comes to
    rest first, that stops the car within `rest_room` [m] (the gap to where the lead
    stops, less the gap to stand at); ego speed v [m/s], room > 0."""
    closing = max(v - max(v_l, 0.0), 0.0)
    a = b + closing * closing / (2.0 * room)
    if b <= 0.0 or closing * max(v_l, 0.0) / b >= 2.0 * room:  # the closing ends first
        return a
    return v * v / (2.0 * rest_room) if rest_room > 0.0 else math.inf


def comfortable(a_need: float, p: AccControlParams) -> bool:
    """Whether a comfortable stop is left when `a_need` [m/s^2] is needed."""
    return a_need <= p.a_comf_max


def ttc(v: float, v_l: float, d: float) -> float:
    """[s] the time to collision with a lead at gap d [m] and speed v_l at the closing speed
    now (ego speed v [m/s]); inf when not closing."""
    closing = v - v_l
    return d / closing if closing > 0.0 and math.isfinite(d) else math.inf


def approach(v: float, law: SpeedRef, a_plan: float, a_need: float, dt: float,
             p: AccControlParams) -> SpeedRef:
    """The law's reference `law`, or, where the car at speed v [m/s] is faster than it and
    the planned deceleration `a_plan` [m/s^2] is gentler than the speed loop's reaction (or
    that reaction exceeds the cap), that deceleration from the car's speed over dt [s];
    never gentler than `a_need` (below the law: only when that leaves no comfortable stop),
    capped at a_comf_max (when a_need exceeds it: a_iso, or a_need up to a_iso_max; a_hard
    beyond). A law whose reaction exceeds the cap is not handed on: the speed loop would brake
    at its comfort envelope's floor on it, while its feed-forward, 0, told `BrakeModel` the
    car had stopped braking, and `need`, counting a whole ramp-in again, jumped from 2.9 to
    12 m/s^2 (UN R157 lead braking at 4 m/s^2 from 60 km/h, its last metres)."""
    loop = max(-law.accel, 0.0) + max(v - law.speed, 0.0) / p.tau_loop
    if v <= law.speed:  # not faster than the law: the law, unless no comfortable stop
        if comfortable(a_need, p):
            return law
        a_plan = loop
    a_plan = max(a_plan, p.a_gentle)  # the law's own reaction is kept up to a_gentle
    a = max(a_need, min(loop, a_plan))
    cap = p.a_comf_max if comfortable(a_need, p) else max(p.a_iso, a_need) \
        if a_need <= p.a_iso_max else p.a_hard
    if a <= loop <= cap and a_plan >= loop:
        return law
    a = min(a, cap)
    return SpeedRef(max(v - a * dt, 0.0), -a)


def follow(v: float, law: SpeedRef, d: float, v_l: float, d_end: float, dt: float,
           p: AccControlParams, a_min: float = 0.0, a_now: float = 0.0,
           a_lead: float = 0.0, d_rest: float = 0.0, entered: bool = False) -> SpeedRef:
    """The approach behind a lead at gap d [m], speed v_l [m/s] and acceleration `a_lead`
    [m/s^2] (signed) on the trail law `law`: the constant deceleration that ends the closing
    at d_end [m] (`closing_plan`; a braking lead that comes to rest first: the car stands
    d_rest [m] behind it), at least `a_min` [m/s^2] while the car is faster than the law;
    `a_now` [m/s^2] the deceleration the car brakes at (`need`); a_min at least the d_min
    guard's (`guard_decel`), which the approach's cap also counts as needed."""
    guard = guard_decel(v, v_l, d, a_lead, p, entered)
    a_min = max(a_min, guard)
    closing = v - max(v_l, 0.0)
    b = lead_braking(a_lead, p)
    if (closing > 0.0 or b > 0.0) and d - d_end > p.arrived:  # the approach to d_end
        rest_room = d + max(v_l, 0.0) ** 2 / (2.0 * b) - d_rest if b > 0.0 else math.inf
        a_plan = max(closing_plan(v, v_l, b, d - d_end, rest_room), a_min)
    elif closing > 0.0:  # inside d_end: the law, or stopping the closing at the floor at
        room = d - p.d_floor  # no more than a_open where the law would brake harder
        a_plan = max(closing * closing / (2.0 * room) if room > 0.0 else math.inf, a_min,
                     p.a_open)
    else:  # not closing: the law, or opening the gap at a_min
        a_plan = a_min if a_min > 0.0 else math.inf
    return approach(v, law, a_plan, max(follow_need(v, v_l, d, p, a_now, a_lead), guard),
                    dt, p)


def follow_need(v: float, v_l: float, d: float, p: AccControlParams, a_now: float,
                a_lead: float) -> float:
    """[m/s^2] `need` behind the lead, judged for a plan within ISO's limits on ISO's own
    envelope: where the lead does not brake, the comfortable ramp-in leaves more than
    a_iso_max but the ramp-in at j_iso to a_iso_max stops the closing, a_iso_max (a plan
    within ISO's limits, not an urgent one at a_hard). A braking lead's deceleration is
    known late (`track_lag`): its plan stays urgent."""
    a = need(v, v_l, d, p, a_now, a_lead)
    if (a > p.a_iso_max and lead_braking(a_lead, p) <= 0.0
            and need(v, v_l, d, p, a_now, a_lead, iso=True) <= p.a_iso_max):
        return p.a_iso_max
    return a


def ramped(v: float, v_end: float, room: float, a_now: float, p: AccControlParams) -> float:
    """[m/s^2] the constant deceleration from v to v_end [m/s] within `room` [m] after the
    ramp-in from `a_now` [m/s^2] at j_comf (the room shortened by v (a - a_now) / (2 j_comf),
    a first estimated without it); inf with no room."""
    if room <= p.arrived:
        return math.inf
    first = max(v * v - v_end * v_end, 0.0) / (2.0 * room)
    left = room - v * max(first - a_now, 0.0) / (2.0 * p.j_comf)
    return max(v * v - v_end * v_end, 0.0) / (2.0 * left) if left > 0.0 else math.inf


def stop(distance: float, v: float, v_plan: float, dt: float, p: AccControlParams,
         a_now: float = 0.0) -> SpeedRef:
    """The stop `margin` before `distance` [m] (`stop_speed`) through the approach from the
    speed v [m/s], braking at `a_now` [m/s^2] now (`ramped`)."""
    speed = stop_speed(distance, v_plan, p)
    law = SpeedRef(speed, -p.a_comf if 0.0 < speed < v_plan else 0.0)
    a_plan = ramped(v, 0.0, distance - p.margin, a_now, p)
    return approach(v, law, a_plan, a_plan if v > speed else 0.0, dt, p) if speed > 0.0 \
        else law


def bump(distance: float, v_pass: float, v: float, v_plan: float, dt: float,
         p: AccControlParams, a_now: float = 0.0) -> SpeedRef:
    """The bump's pass speed (`pass_speed`) through the approach from the speed v [m/s],
    braking at `a_now` [m/s^2] now (`ramped`)."""
    speed = pass_speed(distance, v_pass, v_plan, p)
    law = SpeedRef(speed, -p.a_comf if v_pass < speed < v_plan else 0.0)
    a_plan = ramped(v, v_pass, distance - p.margin, a_now, p) if v > v_pass else 0.0
    return approach(v, law, a_plan, a_plan if v > speed else 0.0, dt, p)


class BrakeModel:
    """The deceleration the car brakes at, as the speed loop builds it from the plan's
    feed-forward: it rises at most at j_comf and falls at once (`control.longitudinal`'s
    comfort envelope); `need` allows for the ramp-in still to come."""

    def __init__(self) -> None:
        self.a = 0.0  # [m/s^2] >= 0

    def reset(self) -> None:
        self.a = 0.0

    def step(self, accel: float, dt: float, p: AccControlParams) -> float:
        """Follow the plan's feed-forward `accel` [m/s^2] (signed) over dt [s]; the
        deceleration now [m/s^2]."""
        self.a = min(max(-accel, 0.0), self.a + p.j_comf * dt)
        return self.a
