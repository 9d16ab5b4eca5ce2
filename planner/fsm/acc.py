"""The ACC / event-driven ACC modes of the DECS paper: the mode FSM and its gaps.

States (the paper's Stateflow chart, Fig. 2): ACC_OFF, and inside ACC_ON either ACC_ACTIVE
{CRUISE, TRAIL, BRAKE, SPEED_LIMIT} or EDACC {OFF_RAMP, PEDESTRIAN, SPEED_BUMP, STOP_SIGN,
FLAT}, plus two modes of our own for town junctions, RED_LIGHT and YIELD. Inputs
(`AccInput`, speeds [m/s], gaps [m]): the bumper gap d to the vehicle ahead in the lane and
its speed V_l (+inf when there is none), the set speed V_s, the posted limit V_GPS (the
paper reads it from the map by GPS; here at the front bumper), the ego speed v, the
deceleration a_need that still stops the closing on the lead and the time to collision ttc
with it (both from `planner.acc_control`: `need`, `ttc`) and the set of discrete events.
The events are decided upstream (`planner.events`,
`planner.junctions`); this module only says which mode holds.

Gaps (the paper gives none; designed here, `gaps`, parameters `AccParams`):

- d_min(v): the UN R157 minimum following distance, ``max(v t_front, 2 m)`` with
  ``t_front = 1.0 + v_kph / 100`` s (v_kph taken as at least 10 km/h);
- d_des(v) = max(d0 + tau v, d_min(v) + tau_margin v): the desired gap, a standstill gap
  d0 plus a time gap tau, never within tau_margin (0.2 s) of d_min: above 70 km/h R157's
  d_min (1 + v / 100 km/h s) exceeds d0 + tau v, and a car that followed at d_min itself
  fell under it with every ripple of its speed or the lead's;
- d_max(v, V_l) = d_des + max(v^2 - V_l^2, 0) / (2 a_comf) + d_reach: the gap inside which
  the lead matters. Beyond it, braking at a_comf from v to V_l still ends at or beyond
  d_des; d_reach is hysteresis.

BRAKE is left for TRAIL once the gap is back ``d_band`` above d_min (hysteresis against the
entry at d_min) and the car no longer closes on the lead (row 23's ``v <= V_l + v_band``):
from there the gap is TRAIL's to open to d_des, which its law approaches from below and
would never pass.

Comfort (ISO 15622 / ISO 22179): a comfortable stop is left while a_need <= a_comf_max
(`planner.limits.A_COMF_MAX`; `planner.acc_control.comfortable` decides, the input says).
When it is not, the ACC enters BRAKE at once, saying so ("no comfortable stop: needs 4.2
m/s^2, ttc 2.1 s"), and BRAKE is left only once a_need is back at or below
a_comf_max - a_hysteresis (`relaxed`), so that a need hovering at the bound does not
flip the mode.

Transitions (`TABLE`, as data): every row of the paper's Table 2, plus the rows a sound
chart needs that the table's "sample" leaves out, and the town modes' rows; rows and parts
of rows the paper has no counterpart for are marked *. For the state the car is in, the rows
that leave it are tried in this order and the first that holds is taken. The events
(`AccEvent`, each with its mode, `EVENT_MODE`) thus take priority in this order: flat tyre,
pedestrian, stop sign, red light, give way, speed bump, off-ramp. An event mode holds while
its own event does, unless a row leaves it for another event's mode (only where the table
has one: a stop sign does not interrupt a speed bump); when its event is over the car
cruises (the chart's default ACC_ACTIVE state), and CRUISE's rows settle the mode on the same
input (`transition`: one change, from the event's mode to the mode they reach).
The rows that leave a lead because it is as fast as the set speed or the limit (V_s <= V_l,
V_GPS <= V_l in Table 2) ask it to be v_band faster (*): a lead driving at the set speed
would otherwise flip TRAIL and CRUISE with every wobble of its measured speed.
And a lead lost leaves TRAIL only after lead_hold (`lead_lost`: no lead now, one within
lead_hold; *): when the lead cuts out, the vehicle it hid becomes the lead once its track
is confirmed, and the mode goes on as TRAIL instead of flipping to CRUISE and back.
Table 2 enters TRAIL from CRUISE and SPEED_LIMIT only beyond d_des: a lead inside d_des but
beyond d_min (the car stood behind it at a red light, or it cut in close but not under
d_min) would leave the car cruising on the speed plan, up into it until a comfortable stop
is gone; those rows start at d_min (*), and TRAIL's law opens the gap to d_des.
Table 2's conditions overlap: out of BRAKE with the lead beyond d_max, Trail's row also
holds, so Cruise and SpeedLimit are tried first.

1. acc_off -> cruise: ACC switched on (the chart's default state)
2. any ACC_ON but flat -> acc_off: ACC switched off *
3. any ACC_ON but flat -> flat: [Flat] (Table 2: SpeedBump -> Flat; from any mode *)
4. ACC_ACTIVE, off_ramp, speed_bump, stop_sign, red_light, yield -> pedestrian: [Pedestrian]
   (from stop sign, red light, yield *)
5. ACC_ACTIVE, off_ramp -> stop_sign: [StopS] (Table 2: OffRamp -> StopSign; from ACC_ACTIVE
   *)
6. ACC_ACTIVE, off_ramp, yield -> red_light: a light ahead to stop for (`planner.junctions`)
   *
7. ACC_ACTIVE, off_ramp -> yield: a gap to wait for at a junction (town) *
8. stop_sign, red_light -> yield: a gap to wait for, the mode's own event over *
9. ACC_ACTIVE -> speed_bump: [SpeedBump] (Table 2: Trail, Brake; Cruise, SpeedLimit *)
10. ACC_ACTIVE -> off_ramp: [Off_Ramp] *
11. off_ramp -> cruise: [!Off_Ramp]
12. pedestrian -> cruise: [!Pedestrian]
13. speed_bump -> cruise: [!SpeedBump]
14. stop_sign -> cruise: [!StopS] (the stop is done) *
15. red_light -> cruise: the light lets the car go *
16. yield -> cruise: the gap has come *
17. cruise, trail, speed_limit -> brake: d <= d_min (Table 2: Cruise -> Brake; Trail,
    SpeedLimit *)
18. cruise, trail, speed_limit -> brake: no comfortable stop (a_need > a_comf_max) *
19. cruise -> trail: d_min < d < d_max and V_l < V_s (Table 2: d_des < d; inside d_des too
    *)
20. trail -> cruise: V_GPS >= V_s and ((d >= d_max + d_let_go and not lead_lost) or (V_s +
    v_band <= V_l and d_min < d < inf)) (d_let_go *)
21. brake -> cruise: V_GPS >= V_s and (d >= d_max or V_s + v_band <= V_l) and d > d_min and
    a_need relaxed *
22. brake -> speed_limit: V_GPS < V_s and (d >= d_max or V_s + v_band <= V_l) and d > d_min
    and a_need relaxed *
23. brake -> trail: (d > d_des or (v <= V_l + v_band and d > d_min + d_band)) and (V_l < V_s
    or V_l < V_GPS) and d > d_min and a_need relaxed *
24. speed_limit -> cruise: V_GPS >= V_s and (d >= d_max or (V_GPS + v_band <= V_l and d >
    d_min))
25. speed_limit -> trail: (V_GPS < V_s or V_l < V_GPS) and d_min < d < d_max (d_des < d:
    inside d_des too *)
26. cruise, trail -> speed_limit: V_GPS < V_s and (d >= d_max (trail: + d_let_go and not
    lead_lost) or (V_GPS + v_band <= V_l and d_min < d < inf)) (Trail *; v_band, lead_lost,
    d_let_go *)

FLAT has no row out: the car stops on the shoulder ("Simulation Stops").
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from planner.fsm.machine import Row, Table, Transition, next_state, render
from planner.limits import A_COMF
from world.frames import to_kph


class AccMode(enum.Enum):
    ACC_OFF = "acc_off"
    CRUISE = "cruise"
    TRAIL = "trail"
    BRAKE = "brake"
    SPEED_LIMIT = "speed_limit"
    OFF_RAMP = "off_ramp"
    PEDESTRIAN = "pedestrian"
    SPEED_BUMP = "speed_bump"
    STOP_SIGN = "stop_sign"
    RED_LIGHT = "red_light"
    YIELD = "yield"
    FLAT = "flat"


class AccEvent(enum.Enum):
    """A discrete event the ACC layer reacts to (decided upstream: `planner.events`,
    `planner.junctions`)."""

    PEDESTRIAN = "pedestrian"  # a pedestrian on or at the crossing ahead
    STOP_SIGN = "stop_sign"  # a stop line ahead not yet stopped at
    RED_LIGHT = "red_light"  # a light ahead to stop for (red, yellow, unread)
    GIVE_WAY = "give_way"  # a junction ahead to wait at for a gap
    SPEED_BUMP = "speed_bump"  # a speed bump ahead within its approach
    OFF_RAMP = "off_ramp"  # on the exit ramp of the route
    FLAT = "flat"  # a flat tyre detected


EVENT_MODE = {  # each event's mode; the events in the order they are tried (priority)
    AccEvent.PEDESTRIAN: AccMode.PEDESTRIAN,
    AccEvent.STOP_SIGN: AccMode.STOP_SIGN,
    AccEvent.RED_LIGHT: AccMode.RED_LIGHT,
    AccEvent.GIVE_WAY: AccMode.YIELD,
    AccEvent.SPEED_BUMP: AccMode.SPEED_BUMP,
    AccEvent.OFF_RAMP: AccMode.OFF_RAMP,
    AccEvent.FLAT: AccMode.FLAT,
}
MODE_EVENT = {mode: event for event, mode in EVENT_MODE.items()}
ACC_ACTIVE = frozenset({AccMode.CRUISE, AccMode.TRAIL, AccMode.BRAKE, AccMode.SPEED_LIMIT})
EDACC = frozenset(EVENT_MODE.values())
ACC_ON = ACC_ACTIVE | EDACC
NO_EVENTS: frozenset[AccEvent] = frozenset()


@dataclass(frozen=True, slots=True)
class AccParams:
    d0: float = 4.0  # [m] standstill gap of d_des
    tau: float = 1.5  # [s] time gap of d_des
    tau_margin: float = 0.2  # [s] d_des is at least this time gap above d_min
    a_comf: float = A_COMF  # [m/s^2] comfortable deceleration (d_max)
    d_reach: float = 10.0  # [m] hysteresis beyond the braking distance (d_max)
    a_hysteresis: float = 0.5  # [m/s^2] BRAKE is left with a_need this far under a_comf_max
    d_band: float = 1.0  # [m] BRAKE is left for TRAIL without closing this far above d_min
    v_band: float = 0.5  # [m/s] a lead counts as faster than a speed once this much faster
    lead_hold: float = 1.0  # [s] TRAIL outlives a lost lead this long (lead_lost): a cut-out
    #   at 2.5 m/s, r157_cut_out_003: the lead left the lane 0.6 s before the stopped car it
    #   had hidden was tracked (at 0.5 s CRUISE was held 0.1 s between)
    d_let_go: float = 2.0  # [m] TRAIL lets a lead go this far beyond d_max (hysteresis
    #   against the entry within d_max: a gap about d_max flicked TRAIL and CRUISE a tick)


@dataclass(frozen=True, slots=True)
class AccInput:
    acc_on: bool  # the driver's ACC switch (on: a set speed > 0)
    v: float  # [m/s] ego speed
    v_s: float  # [m/s] set speed
    v_gps: float  # [m/s] posted limit in force at the front bumper
    d: float = math.inf  # [m] gap to the vehicle ahead in the lane (+inf: none)
    v_l: float = math.inf  # [m/s] its speed over ground (+inf: none)
    events: frozenset[AccEvent] = NO_EVENTS  # the events that hold now
    a_need: float = 0.0  # [m/s^2] the least deceleration that still stops the closing on
    #   the lead (`planner.acc_control.need`; 0: not closing)
    ttc: float = math.inf  # [s] time to collision with the lead at the closing speed now
    comfortable: bool = True  # a comfortable stop is left (`planner.acc_control.comfortable`)
    relaxed: bool = True  # ... with a_hysteresis to spare (module doc)
    lead_lost: bool = False  # no lead now, but one within lead_hold (module doc)


@dataclass(frozen=True, slots=True)
class Gaps:
    d_min: float  # [m] UN R157 minimum following distance
    d_des: float  # [m] desired gap
    d_max: float  # [m] gap inside which the lead matters
    v_band: float = 0.5  # [m/s] the speed hysteresis of the rows that leave a lead
    #   (`AccParams.v_band`)
    d_band: float = 1.0  # [m] the gap hysteresis of BRAKE's way out to TRAIL (`AccParams`)
    d_let_go: float = 2.0  # [m] the gap hysteresis of TRAIL's way out (`AccParams`)


def r157_min_gap(v: float) -> float:
    """[m] UN R157's minimum following distance at ego speed v [m/s]."""
    t_front = 1.0 + max(to_kph(v), 10.0) / 100.0
    return max(v * t_front, 2.0)


def gaps(v: float, v_l: float, p: AccParams) -> Gaps:
    """The three gaps for ego speed v and lead speed v_l [m/s] (see the module doc)."""
    d_min = r157_min_gap(v)
    d_des = max(p.d0 + p.tau * v, d_min + p.tau_margin * v)
    closing = max(v * v - min(v_l, v) ** 2, 0.0) / (2.0 * p.a_comf)
    return Gaps(d_min, d_des, d_des + closing + p.d_reach, p.v_band, p.d_band, p.d_let_go)


def sight_speed(sight: float, p: AccParams, a_stop: float, t_react: float = 0.5,
                floor: float = 2.5) -> float:
    """[m/s] the fastest speed at which the car's forward sensing, which finds a vehicle
    ahead `sight` [m] away, still covers (a) the desired gap d_des(v) (`gaps`): faster, a
    lead followed at d_des is out of sight, and the car drives on it unseen until it is
    inside that range and under UN R157's d_min, which grows as v^2 (1 + v / 100 km/h s);
    and (b) the stop behind a vehicle standing in the lane, found at `sight`: `t_react` [s]
    to react, then braking at `a_stop` [m/s^2], to rest `floor` [m] short of it."""
    low, high = 0.0, 100.0
    for _ in range(60):  # both sides rise with v: bisection
        mid = 0.5 * (low + high)
        stop = mid * t_react + mid * mid / (2.0 * a_stop) + floor
        low, high = (mid, high) if max(gaps(mid, mid, p).d_des, stop) <= sight else (low, mid)
    return low


# -- the guards: (mode now, input, gaps) -> the row holds --------------------------------------


def _switched_on(_m: AccMode, x: AccInput, _g: Gaps) -> bool:
    return x.acc_on


def _switched_off(_m: AccMode, x: AccInput, _g: Gaps) -> bool:
    return not x.acc_on


def _own_event_over(m: AccMode, x: AccInput, _g: Gaps) -> bool:
    return MODE_EVENT[m] not in x.events


class _Event:
    """The row holds while `event` does (and, `after_own`, once the mode's own is over)."""

    def __init__(self, event: AccEvent, after_own: bool = False) -> None:
        self.event, self.after_own = event, after_own

    def __call__(self, m: AccMode, x: AccInput, g: Gaps) -> bool:
        return self.event in x.events and (not self.after_own or _own_event_over(m, x, g))


def _too_close(_m: AccMode, x: AccInput, g: Gaps) -> bool:
    return x.d <= g.d_min


def _comfortable(x: AccInput, _g: Gaps) -> bool:
    """A comfortable stop is left, with the hysteresis to spare (module doc)."""
    return x.comfortable and x.relaxed


def _no_comfortable_stop(_m: AccMode, x: AccInput, _g: Gaps) -> bool:
    return not x.comfortable


def _why_hard(x: AccInput, _g: Gaps) -> str:
    return f"no comfortable stop: needs {min(x.a_need, 99.0):.1f} m/s^2, ttc {x.ttc:.1f} s"


def _beyond(m: AccMode, x: AccInput, g: Gaps) -> bool:
    """The lead is beyond d_max (TRAIL: by d_let_go, and not just lost)."""
    if m is AccMode.TRAIL:
        return x.d >= g.d_max + g.d_let_go and not x.lead_lost
    return x.d >= g.d_max


def _to_limit(m: AccMode, x: AccInput, g: Gaps) -> bool:
    return x.v_gps < x.v_s and (_beyond(m, x, g)
                                or (x.v_gps + g.v_band <= x.v_l and g.d_min < x.d < math.inf))


def _cruise_to_trail(_m: AccMode, x: AccInput, g: Gaps) -> bool:
    return g.d_min < x.d < g.d_max and x.v_l < x.v_s


def _trail_to_cruise(m: AccMode, x: AccInput, g: Gaps) -> bool:
    return x.v_gps >= x.v_s and (_beyond(m, x, g)
                                 or (x.v_s + g.v_band <= x.v_l and g.d_min < x.d < math.inf))


def _brake_to_cruise(_m: AccMode, x: AccInput, g: Gaps) -> bool:
    return (x.v_gps >= x.v_s and (x.d >= g.d_max or x.v_s + g.v_band <= x.v_l) and x.d > g.d_min
            and _comfortable(x, g))


def _brake_to_limit(_m: AccMode, x: AccInput, g: Gaps) -> bool:
    return (x.v_gps < x.v_s and (x.d >= g.d_max or x.v_s + g.v_band <= x.v_l) and x.d > g.d_min
            and _comfortable(x, g))


def _brake_to_trail(_m: AccMode, x: AccInput, g: Gaps) -> bool:
    recovered = x.d > g.d_des or (x.v <= x.v_l + g.v_band and x.d > g.d_min + g.d_band)
    return (recovered and (x.v_l < x.v_s or x.v_l < x.v_gps) and x.d > g.d_min
            and _comfortable(x, g))


def _limit_to_cruise(_m: AccMode, x: AccInput, g: Gaps) -> bool:
    return x.v_gps >= x.v_s and (x.d >= g.d_max or (x.v_gps + g.v_band <= x.v_l and x.d > g.d_min))


def _limit_to_trail(_m: AccMode, x: AccInput, g: Gaps) -> bool:
    return (x.v_gps < x.v_s or x.v_l < x.v_gps) and g.d_min < x.d < g.d_max


# -- the table --------------------------------------------------------------------------------

M = AccMode
AccRow = Row[AccMode, AccInput, Gaps]


def _done(mode: AccMode, when: str) -> AccRow:
    return Row(frozenset({mode}), M.CRUISE, _own_event_over, when, f"{mode.value} done")


TABLE: Table[AccMode, AccInput, Gaps] = Table(AccMode, (
    Row(frozenset({M.ACC_OFF}), M.CRUISE, _switched_on,
        "ACC switched on (the chart's default state)", "ACC switched on"),
    Row(ACC_ON - {M.FLAT}, M.ACC_OFF, _switched_off, "ACC switched off *",
        "ACC switched off"),
    Row(ACC_ON - {M.FLAT}, M.FLAT, _Event(AccEvent.FLAT),
        "[Flat] (Table 2: SpeedBump -> Flat; from any mode *)", "flat tyre"),
    Row(ACC_ACTIVE | {M.OFF_RAMP, M.SPEED_BUMP, M.STOP_SIGN, M.RED_LIGHT, M.YIELD},
        M.PEDESTRIAN, _Event(AccEvent.PEDESTRIAN),
        "[Pedestrian] (from stop sign, red light, yield *)",
        "a pedestrian at the crossing ahead"),
    Row(ACC_ACTIVE | {M.OFF_RAMP}, M.STOP_SIGN, _Event(AccEvent.STOP_SIGN),
        "[StopS] (Table 2: OffRamp -> StopSign; from ACC_ACTIVE *)", "a stop line ahead"),
    Row(ACC_ACTIVE | {M.OFF_RAMP, M.YIELD}, M.RED_LIGHT, _Event(AccEvent.RED_LIGHT),
        "a light ahead to stop for (`planner.junctions`) *",
        "a traffic light ahead to stop for"),
    Row(ACC_ACTIVE | {M.OFF_RAMP}, M.YIELD, _Event(AccEvent.GIVE_WAY),
        "a gap to wait for at a junction (town) *", "giving way at the junction ahead"),
    Row(frozenset({M.RED_LIGHT, M.STOP_SIGN}), M.YIELD,
        _Event(AccEvent.GIVE_WAY, after_own=True),
        "a gap to wait for, the mode's own event over *", "giving way at the junction ahead"),
    Row(ACC_ACTIVE, M.SPEED_BUMP, _Event(AccEvent.SPEED_BUMP),
        "[SpeedBump] (Table 2: Trail, Brake; Cruise, SpeedLimit *)", "a speed bump ahead"),
    Row(ACC_ACTIVE, M.OFF_RAMP, _Event(AccEvent.OFF_RAMP), "[Off_Ramp] *",
        "on the exit ramp"),
    _done(M.OFF_RAMP, "[!Off_Ramp]"),
    _done(M.PEDESTRIAN, "[!Pedestrian]"),
    _done(M.SPEED_BUMP, "[!SpeedBump]"),
    _done(M.STOP_SIGN, "[!StopS] (the stop is done) *"),
    _done(M.RED_LIGHT, "the light lets the car go *"),
    _done(M.YIELD, "the gap has come *"),
    Row(frozenset({M.CRUISE, M.TRAIL, M.SPEED_LIMIT}), M.BRAKE, _too_close,
        "d <= d_min (Table 2: Cruise -> Brake; Trail, SpeedLimit *)",
        "gap at or below d_min"),
    Row(frozenset({M.CRUISE, M.TRAIL, M.SPEED_LIMIT}), M.BRAKE, _no_comfortable_stop,
        "no comfortable stop (a_need > a_comf_max) *", _why_hard),
    Row(frozenset({M.CRUISE}), M.TRAIL, _cruise_to_trail,
        "d_min < d < d_max and V_l < V_s (Table 2: d_des < d; inside d_des too *)",
        "a slower vehicle ahead within d_max"),
    Row(frozenset({M.TRAIL}), M.CRUISE, _trail_to_cruise,
        "V_GPS >= V_s and ((d >= d_max + d_let_go and not lead_lost) or (V_s + v_band <= "
        "V_l and d_min < d < inf)) (d_let_go *)",
        "the lead is gone or faster than the set speed"),
    Row(frozenset({M.BRAKE}), M.CRUISE, _brake_to_cruise,
        "V_GPS >= V_s and (d >= d_max or V_s + v_band <= V_l) and d > d_min and a_need "
        "relaxed *",
        "gap recovered, nothing slower ahead"),
    Row(frozenset({M.BRAKE}), M.SPEED_LIMIT, _brake_to_limit,
        "V_GPS < V_s and (d >= d_max or V_s + v_band <= V_l) and d > d_min and a_need "
        "relaxed *",
        "gap recovered, the posted limit binds"),
    Row(frozenset({M.BRAKE}), M.TRAIL, _brake_to_trail,
        "(d > d_des or (v <= V_l + v_band and d > d_min + d_band)) and (V_l < V_s or V_l < "
        "V_GPS) and d > d_min and a_need relaxed *",
        "gap recovered above d_min, no longer closing on the vehicle ahead"),
    Row(frozenset({M.SPEED_LIMIT}), M.CRUISE, _limit_to_cruise,
        "V_GPS >= V_s and (d >= d_max or (V_GPS + v_band <= V_l and d > d_min))",
        "the posted limit is no longer below the set speed"),
    Row(frozenset({M.SPEED_LIMIT}), M.TRAIL, _limit_to_trail,
        "(V_GPS < V_s or V_l < V_GPS) and d_min < d < d_max (d_des < d: inside d_des too *)",
        "a vehicle ahead within d_max"),
    Row(frozenset({M.CRUISE, M.TRAIL}), M.SPEED_LIMIT, _to_limit,
        "V_GPS < V_s and (d >= d_max (trail: + d_let_go and not lead_lost) or (V_GPS + "
        "v_band <= V_l and d_min < d < inf)) (Trail *; v_band, lead_lost, d_let_go *)",
        "the posted limit is below the set speed"),
))


def transition(mode: AccMode, x: AccInput, p: AccParams) -> Transition[AccMode] | None:
    """The change of mode for input `x`, or None to stay (`TABLE`). A row into CRUISE from
    outside ACC_ACTIVE (ACC switched on, an event over) enters the chart's default state,
    which the same input then settles: CRUISE's own rows are tried at once, and the change
    is the one to the mode they reach (so a mode is never held for a single tick)."""
    g = gaps(x.v, x.v_l, p)
    step = next_state(TABLE, mode, x, g)
    if step is None or step.to is not M.CRUISE or mode in ACC_ACTIVE:
        return step
    settled = next_state(TABLE, M.CRUISE, x, g)
    if settled is None or settled.to is mode:
        return step
    return Transition(settled.to, f"{step.reason}; {settled.reason}")


def source_names(states: frozenset[AccMode]) -> str:
    """A row's source states for the docs: the chart's groups by name where a row leaves a
    whole group, then the single modes."""
    parts, rest = [], set(states)
    for name, group in (("any ACC_ON but flat", ACC_ON - {M.FLAT}),
                        ("ACC_ACTIVE", ACC_ACTIVE)):
        if group <= rest:
            parts.append(name)
            rest -= group
    parts += [m.value for m in AccMode if m in rest]
    return ", ".join(parts)


def table_text() -> str:
    """`TABLE` as the module doc shows it."""
    return render(TABLE, names=source_names)


if __name__ == "__main__":  # print the table for the module doc
    print(table_text())
