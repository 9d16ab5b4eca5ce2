"""The ACC / event-driven ACC layer of the DECS paper: its mode FSM and its gaps.

States (the paper's Stateflow chart, Fig. 2): ACC_OFF, and inside ACC_ON either ACC_ACTIVE
{CRUISE, TRAIL, BRAKE, SPEED_LIMIT} or EDACC {OFF_RAMP, PEDESTRIAN, SPEED_BUMP, STOP_SIGN,
FLAT}, plus two of our own for town junctions, RED_LIGHT and YIELD (their rows are marked *
in the table, as are the rows the paper's chart has no counterpart for). Inputs
(`AccInput`): the gap d to the vehicle ahead in the lane and its speed V_l (+inf when there
is none), the set speed V_s, the posted limit where the car is V_GPS (the
paper reads it from the map by GPS), the ego speed v and the discrete events.

Gaps (the paper gives none; designed here, all in metres, speeds in m/s):

- d_min(v): the UN R157 minimum following distance, ``max(v t_front, 2 m)`` with
  ``t_front = 1.0 + v_kph / 100`` s (v_kph taken as at least 10 km/h below 10 km/h);
- d_des(v) = max(d0 + tau v, d_min(v)): the desired gap, a standstill gap d0 (4 m) plus a
  time gap tau (1.5 s), never below d_min;
- d_max(v, V_l) = d_des + max(v^2 - V_l^2, 0) / (2 a_comf) + d_reach: the gap inside which
  the lead matters. Beyond it, braking at a_comf (1.5 m/s^2) from v to V_l still ends at
  d_des, with d_reach (10 m) of hysteresis.

Transitions: every row of the paper's Table 2, plus the ones a sound chart needs and the
table's "sample" leaves out (marked * below). Within a state they are tried in this order,
and the first that holds is taken (Table 2's conditions overlap: out of BRAKE with the lead
beyond d_max, Trail's row also holds, so Cruise and SpeedLimit are tried first):

| from               | to          | when                                                   |
|--------------------|-------------|--------------------------------------------------------|
| ACC_OFF            | CRUISE      | ACC switched on (the chart's default state)            |
| any but FLAT*      | ACC_OFF     | ACC switched off                                       |
| any ACC_ON*        | FLAT        | flat tyre (Table 2: SpeedBump -> Flat)                 |
| ACC_ACTIVE, OFF_RAMP, SPEED_BUMP, STOP_SIGN*, RED_LIGHT*, YIELD* | PEDESTRIAN | [Pedestrian] |
| ACC_ACTIVE*, OFF_RAMP | STOP_SIGN | [StopS] (Table 2: OffRamp -> StopSign)                  |
| ACC_ACTIVE*, OFF_RAMP*, YIELD* | RED_LIGHT | a light ahead to stop for (`planner.junctions`) |
| ACC_ACTIVE*, OFF_RAMP*, RED_LIGHT*, STOP_SIGN* | YIELD | a gap to wait for at a junction (town) |
| ACC_ACTIVE         | SPEED_BUMP  | [SpeedBump] (Table 2: Trail, Brake)                    |
| ACC_ACTIVE*        | OFF_RAMP    | [Off_Ramp]                                             |
| CRUISE, TRAIL*, SPEED_LIMIT* | BRAKE | d <= d_min (Table 2: Cruise -> Brake)           |
| CRUISE             | TRAIL       | d < d_max and d > d_des and V_l < V_s                  |
| CRUISE, TRAIL*     | SPEED_LIMIT | V_GPS < V_s and (d >= d_max or (V_GPS <= V_l and d > d_min)) |
| TRAIL              | CRUISE      | V_GPS >= V_s and (d >= d_max or (V_s <= V_l and d > d_min)) |
| BRAKE              | CRUISE      | V_GPS >= V_s and (d >= d_max or V_s <= V_l) and d > d_min |
| BRAKE              | SPEED_LIMIT | V_GPS < V_s and (d >= d_max or V_s <= V_l) and d > d_min |
| BRAKE              | TRAIL       | d > d_des and (V_l < V_s or V_l < V_GPS) and d > d_min |
| SPEED_LIMIT        | CRUISE      | V_GPS >= V_s and (d >= d_max or (V_GPS <= V_l and d > d_min)) |
| SPEED_LIMIT        | TRAIL       | (V_GPS < V_s or V_l < V_GPS) and d < d_max and d > d_des |
| OFF_RAMP           | CRUISE      | [!Off_Ramp]                                            |
| PEDESTRIAN         | CRUISE      | [!Pedestrian]                                          |
| SPEED_BUMP         | CRUISE      | [!SpeedBump]                                           |
| STOP_SIGN*         | CRUISE      | [!StopS] (the stop is done)                            |
| RED_LIGHT*, YIELD* | CRUISE      | the light lets the car go / the gap has come           |
| FLAT               | -           | none: the car stops on the shoulder ("Simulation Stops") |

The ACC_ACTIVE mode after an event is CRUISE (the chart's default); the next tick's
transitions settle it. The events are decided upstream (perception and the map); this
module only says which mode holds.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable
from dataclasses import dataclass

KPH = 1.0 / 3.6  # [m/s per km/h]


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


ACC_ACTIVE = frozenset({AccMode.CRUISE, AccMode.TRAIL, AccMode.BRAKE, AccMode.SPEED_LIMIT})
EDACC = frozenset({AccMode.OFF_RAMP, AccMode.PEDESTRIAN, AccMode.SPEED_BUMP, AccMode.STOP_SIGN,
                   AccMode.RED_LIGHT, AccMode.YIELD, AccMode.FLAT})


@dataclass(frozen=True, slots=True)
class AccParams:
    d0: float = 4.0  # [m] standstill gap of d_des
    tau: float = 1.5  # [s] time gap of d_des
    a_comf: float = 1.5  # [m/s^2] comfortable deceleration (d_max)
    d_reach: float = 10.0  # [m] hysteresis beyond the braking distance (d_max)


@dataclass(frozen=True, slots=True)
class AccInput:
    acc_on: bool  # the driver's ACC switch (with a set speed)
    v: float  # [m/s] ego speed
    v_s: float  # [m/s] set speed
    v_gps: float  # [m/s] posted limit where the car is
    d: float = math.inf  # [m] gap to the vehicle ahead in the lane (+inf: none)
    v_l: float = math.inf  # [m/s] its speed over ground (+inf: none)
    off_ramp: bool = False  # on the exit ramp of the route
    pedestrian: bool = False  # a pedestrian on or at the crossing ahead
    speed_bump: bool = False  # a speed bump ahead within its approach
    stop_sign: bool = False  # a stop line ahead not yet stopped at
    red_light: bool = False  # a light ahead to stop for (red, yellow, unread)
    give_way: bool = False  # a junction ahead to wait at for a gap
    flat: bool = False  # a flat tyre detected


@dataclass(frozen=True, slots=True)
class Gaps:
    d_min: float  # [m]
    d_des: float  # [m]
    d_max: float  # [m]


def r157_min_gap(v: float) -> float:
    """[m] UN R157's minimum following distance at ego speed v [m/s]."""
    t_front = 1.0 + max(v / KPH, 10.0) / 100.0
    return max(v * t_front, 2.0)


def gaps(v: float, v_l: float, p: AccParams) -> Gaps:
    """The three gaps for ego speed v and lead speed v_l [m/s] (see the module doc)."""
    d_min = r157_min_gap(v)
    d_des = max(p.d0 + p.tau * v, d_min)
    closing = max(v * v - min(v_l, v) ** 2, 0.0) / (2.0 * p.a_comf)
    return Gaps(d_min, d_des, d_des + closing + p.d_reach)


@dataclass(frozen=True, slots=True)
class AccChange:
    to: AccMode
    reason: str


Rule = tuple[AccMode, Callable[[AccInput, Gaps], bool], str]


def _following_rules() -> dict[AccMode, list[Rule]]:
    """The ACC_ACTIVE rows of the table, per state, in the order they are tried."""
    c, t, b, s = AccMode.CRUISE, AccMode.TRAIL, AccMode.BRAKE, AccMode.SPEED_LIMIT

    def too_close(x: AccInput, g: Gaps) -> bool:
        return x.d <= g.d_min

    def to_limit(x: AccInput, g: Gaps) -> bool:
        return x.v_gps < x.v_s and (x.d >= g.d_max or (x.v_gps <= x.v_l and x.d > g.d_min))

    brake = (b, too_close, "gap at or below d_min")
    limit = (s, to_limit, "the posted limit is below the set speed")
    return {
        c: [brake,
            (t, lambda x, g: g.d_des < x.d < g.d_max and x.v_l < x.v_s,
             "a slower vehicle ahead within d_max"),
            limit],
        t: [brake,
            (c, lambda x, g: x.v_gps >= x.v_s and (
                x.d >= g.d_max or (x.v_s <= x.v_l and x.d > g.d_min)),
             "the lead is gone or faster than the set speed"),
            limit],
        b: [(c, lambda x, g: x.v_gps >= x.v_s and (x.d >= g.d_max or x.v_s <= x.v_l)
             and x.d > g.d_min, "gap recovered, nothing slower ahead"),
            (s, lambda x, g: x.v_gps < x.v_s and (x.d >= g.d_max or x.v_s <= x.v_l)
             and x.d > g.d_min, "gap recovered, the posted limit binds"),
            (t, lambda x, g: x.d > g.d_des and (x.v_l < x.v_s or x.v_l < x.v_gps)
             and x.d > g.d_min, "gap recovered beyond d_des behind a slower vehicle")],
        s: [brake,
            (c, lambda x, g: x.v_gps >= x.v_s and (
                x.d >= g.d_max or (x.v_gps <= x.v_l and x.d > g.d_min)),
             "the posted limit is no longer below the set speed"),
            (t, lambda x, g: (x.v_gps < x.v_s or x.v_l < x.v_gps) and g.d_des < x.d < g.d_max,
             "a vehicle ahead within d_max")],
    }


_FOLLOWING = _following_rules()

# event entries, by priority: (flag, mode, reason); OFF_RAMP and SPEED_BUMP only from
# ACC_ACTIVE, PEDESTRIAN and STOP_SIGN also from the other events (Table 2)
_EVENTS: tuple[tuple[str, AccMode, str], ...] = (
    ("pedestrian", AccMode.PEDESTRIAN, "a pedestrian at the crossing ahead"),
    ("stop_sign", AccMode.STOP_SIGN, "a stop line ahead"),
    ("red_light", AccMode.RED_LIGHT, "a traffic light ahead to stop for"),
    ("give_way", AccMode.YIELD, "giving way at the junction ahead"),
    ("speed_bump", AccMode.SPEED_BUMP, "a speed bump ahead"),
    ("off_ramp", AccMode.OFF_RAMP, "on the exit ramp"),
)
_ENTERED_FROM_EVENTS = {
    AccMode.PEDESTRIAN: frozenset({AccMode.OFF_RAMP, AccMode.SPEED_BUMP, AccMode.STOP_SIGN,
                                   AccMode.RED_LIGHT, AccMode.YIELD}),
    AccMode.STOP_SIGN: frozenset({AccMode.OFF_RAMP}),
    AccMode.RED_LIGHT: frozenset({AccMode.OFF_RAMP, AccMode.YIELD}),
    AccMode.YIELD: frozenset({AccMode.OFF_RAMP, AccMode.RED_LIGHT, AccMode.STOP_SIGN}),
}
_CLEARS = {AccMode.OFF_RAMP: "off_ramp", AccMode.PEDESTRIAN: "pedestrian",
           AccMode.SPEED_BUMP: "speed_bump", AccMode.STOP_SIGN: "stop_sign",
           AccMode.RED_LIGHT: "red_light", AccMode.YIELD: "give_way"}


def transition(mode: AccMode, x: AccInput, p: AccParams) -> AccChange | None:
    """The change of mode for input `x`, or None to stay (see the module doc's table)."""
    if mode is AccMode.FLAT:
        return None
    if mode is AccMode.ACC_OFF:
        return AccChange(AccMode.CRUISE, "ACC switched on") if x.acc_on else None
    if not x.acc_on:
        return AccChange(AccMode.ACC_OFF, "ACC switched off")
    if x.flat:
        return AccChange(AccMode.FLAT, "flat tyre")
    event = _event_change(mode, x)
    if event is not None:
        return event
    if mode in EDACC:
        if getattr(x, _CLEARS[mode]):
            return None  # the event still holds
        return AccChange(AccMode.CRUISE, f"{mode.value} done")
    g = gaps(x.v, x.v_l, p)
    for to, holds, reason in _FOLLOWING[mode]:
        if holds(x, g):
            return AccChange(to, reason)
    return None


def _event_change(mode: AccMode, x: AccInput) -> AccChange | None:
    for flag, to, reason in _EVENTS:
        if not getattr(x, flag):
            continue
        if to is mode:
            return None  # the mode's own event holds: only a higher one may take over
        if mode in ACC_ACTIVE or mode in _ENTERED_FROM_EVENTS.get(to, frozenset()):
            return AccChange(to, reason)
    return None
