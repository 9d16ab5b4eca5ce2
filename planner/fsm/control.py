"""The Control FSM (C-FSM) of the ICCAS 2020 paper: which control action holds.

States (the paper's Fig. 3a): STOP, EMERGENCY_STOP, ACCELERATION, DECELERATION and
SPEED_KEEPING. The paper names them and says the changes follow the recognised objects,
lights and signs; it gives no conditions, so these are designed here. Inputs
(`ControlInput`, speeds [m/s], accelerations [m/s^2]): the ego speed v, the planner's target
speed v_target and feed-forward acceleration a_target after the ACC layer, the deceleration
a_required needed to avoid the vehicle ahead and the time to collision ttc [s] with it (both
computed upstream: `required_deceleration`, `time_to_collision`).

Terms (the thresholds are `ControlParams`):

- moving: v >= v_stopped; stopped otherwise. A stopped car has no emergency.
- threat: a_required >= a_emergency_enter (more than the ACC's BRAKE mode plans) or
  ttc < ttc_emergency. It is over when a_required < a_emergency_exit and the gap does not
  close (ttc infinite): braking hard, the car closes more slowly, so a finite TTC or a
  falling a_required says the braking works, not that the threat is gone (AEB practice,
  and ICCAS: the car "stops the same when the deceleration exceeds a threshold"). The
  gap between the two thresholds keeps EMERGENCY_STOP from chattering.
- slow down (D): v - v_target > speed_band or a_target < -accel_band.
- speed up (A): (v_target - v > speed_band or a_target > accel_band), not D and no threat.
  Slowing down wins when the speed error and the plan's acceleration disagree (a target
  above the speed but a braking feed-forward, or the reverse): otherwise ACCELERATION and
  DECELERATION would swap every tick. A threat keeps a stopped car (below v_stopped, so no
  emergency) from starting into it; a moving car under a threat is in EMERGENCY_STOP first.
- on target: |v_target - v| <= keep_band and |a_target| <= accel_band (keep_band is
  narrower than speed_band: the hysteresis of SPEED_KEEPING).

Transitions (`TABLE`, as data). For the state the car is in, the rows that leave it are
tried in this order and the first that holds is taken: the emergency first, then the stop,
then the rest (whose conditions exclude each other):

1. stop, acceleration, deceleration, speed_keeping -> emergency_stop: moving and a_required
   >= a_emergency_enter
2. stop, acceleration, deceleration, speed_keeping -> emergency_stop: moving and ttc <
   ttc_emergency
3. emergency_stop -> stop: v < v_stopped ("stopped", whatever the threat)
4. emergency_stop -> deceleration: moving and the threat is over
5. stop -> acceleration: v_target > v_start and no threat
6. acceleration, deceleration, speed_keeping -> stop: v < v_stopped and v_target <= v_start
7. deceleration, speed_keeping -> acceleration: speed up (A)
8. acceleration, speed_keeping -> deceleration: slow down (D)
9. acceleration, deceleration -> speed_keeping: on target

Anything else stays. In particular STOP holds while v_target <= v_start (v_start above
v_stopped is the start/stop hysteresis), and also when a stopped car creeps above v_stopped
with no target to start (the speed loop holds it). The C-FSM only says which action holds;
the speed reference stays the planner's.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable
from dataclasses import dataclass

from planner.fsm.machine import Row, Table, Transition, next_state, render
from planner.limits import A_HARD


class ControlState(enum.Enum):
    STOP = "stop"
    EMERGENCY_STOP = "emergency_stop"
    ACCELERATION = "acceleration"
    DECELERATION = "deceleration"
    SPEED_KEEPING = "speed_keeping"


@dataclass(frozen=True, slots=True)
class ControlParams:
    a_emergency_enter: float = A_HARD  # [m/s^2] required deceleration at/above it: emergency
    ttc_emergency: float = 1.2  # [s] time to collision below it: an emergency
    a_emergency_exit: float = 2.5  # [m/s^2] the threat is over below it (and the gap opens)
    v_stopped: float = 0.1  # [m/s] below it the car is stopped
    v_start: float = 0.5  # [m/s] a target speed above it starts the car from STOP
    speed_band: float = 0.5  # [m/s] speed error beyond which SPEED_KEEPING speeds up / slows
    keep_band: float = 0.2  # [m/s] speed error within which the car settles to SPEED_KEEPING
    accel_band: float = 0.3  # [m/s^2] |a_target| above it: the plan itself speeds up / slows


@dataclass(frozen=True, slots=True)
class ControlInput:
    v: float  # [m/s] ego speed
    v_target: float  # [m/s] the planner's target speed (after the ACC layer)
    a_target: float = 0.0  # [m/s^2] its feed-forward acceleration, signed
    a_required: float = 0.0  # [m/s^2] >= 0: deceleration needed to avoid the lead (0: none)
    ttc: float = math.inf  # [s] time to collision with the lead (+inf: none or opening)


def required_deceleration(v: float, d: float, v_l: float, a_l: float,
                          d_stop: float = 1.0) -> float:
    """[m/s^2] >= 0: the deceleration that keeps the ego `d_stop` [m] behind the vehicle ahead.

    d: the bumper-to-bumper gap [m] (+inf: no lead); v: the ego speed, v_l the lead's speed
    [m/s]; a_l the lead's acceleration [m/s^2], signed (< 0: braking). The larger of

    - the lead brakes (a_l < -0.5): it stops within ``D_l = v_l^2 / (2 |a_l|)`` (v_l taken
      as at least 0), and the ego must stop within ``d + D_l - d_stop``:
      ``v^2 / (2 max(d + D_l - d_stop, 0.1 m))``;
    - the ego is faster (v > v_l): at a constant lead speed it must shed the closing speed
      before the gap shrinks to d_stop: ``(v - v_l)^2 / (2 max(d - d_stop, 0.1 m))``;

    and 0 when neither applies (an opening gap behind a lead that does not brake).
    """
    need = 0.0
    if a_l < -0.5:
        lead_stop = max(v_l, 0.0) ** 2 / (2.0 * abs(a_l))
        need = v * v / (2.0 * max(d + lead_stop - d_stop, 0.1))
    if v > v_l:
        need = max(need, (v - v_l) ** 2 / (2.0 * max(d - d_stop, 0.1)))
    return need


def time_to_collision(d: float, v: float, v_l: float) -> float:
    """[s] the time until the gap d [m] closes at the present speeds (ego v, lead v_l, m/s):
    ``d / (v - v_l)`` when the ego is faster, +inf otherwise; 0 when d <= 0 (touching)."""
    if d <= 0.0:
        return 0.0
    if v > v_l:
        return d / (v - v_l)
    return math.inf


def _moving(x: ControlInput, p: ControlParams) -> bool:
    return x.v >= p.v_stopped


def _threat(x: ControlInput, p: ControlParams) -> bool:
    return x.a_required >= p.a_emergency_enter or x.ttc < p.ttc_emergency


def _threat_over(x: ControlInput, p: ControlParams) -> bool:
    return x.a_required < p.a_emergency_exit and math.isinf(x.ttc)


def _slow_down(x: ControlInput, p: ControlParams) -> bool:
    return x.v - x.v_target > p.speed_band or x.a_target < -p.accel_band


def _speed_up(x: ControlInput, p: ControlParams) -> bool:
    wants = x.v_target - x.v > p.speed_band or x.a_target > p.accel_band
    return wants and not _slow_down(x, p) and not _threat(x, p)


def _on_target(x: ControlInput, p: ControlParams) -> bool:
    return abs(x.v_target - x.v) <= p.keep_band and abs(x.a_target) <= p.accel_band


# -- the guards of the table: (state now, input, parameters) -> the row holds ------------------


def _hard_braking_needed(_s: ControlState, x: ControlInput, p: ControlParams) -> bool:
    return _moving(x, p) and x.a_required >= p.a_emergency_enter


def _collision_close(_s: ControlState, x: ControlInput, p: ControlParams) -> bool:
    return _moving(x, p) and x.ttc < p.ttc_emergency


def _stopped(_s: ControlState, x: ControlInput, p: ControlParams) -> bool:
    return not _moving(x, p)


def _moving_threat_over(_s: ControlState, x: ControlInput, p: ControlParams) -> bool:
    return _moving(x, p) and _threat_over(x, p)


def _start(_s: ControlState, x: ControlInput, p: ControlParams) -> bool:
    return x.v_target > p.v_start and not _threat(x, p)


def _stop(_s: ControlState, x: ControlInput, p: ControlParams) -> bool:
    return x.v < p.v_stopped and x.v_target <= p.v_start


def _guard(test: Callable[[ControlInput, ControlParams], bool]) -> ControlGuard:
    def holds(_s: ControlState, x: ControlInput, p: ControlParams) -> bool:
        return test(x, p)
    return holds


S = ControlState
ControlGuard = Callable[[ControlState, ControlInput, ControlParams], bool]
_DRIVING = frozenset({S.ACCELERATION, S.DECELERATION, S.SPEED_KEEPING})
_EMERGENCY_FROM = _DRIVING | {S.STOP}

TABLE: Table[ControlState, ControlInput, ControlParams] = Table(ControlState, (
    Row(_EMERGENCY_FROM, S.EMERGENCY_STOP, _hard_braking_needed,
        "moving and a_required >= a_emergency_enter",
        "required deceleration at or above a_emergency_enter (beyond the ACC's braking)"),
    Row(_EMERGENCY_FROM, S.EMERGENCY_STOP, _collision_close, "moving and ttc < ttc_emergency",
        "time to collision below ttc_emergency"),
    Row(frozenset({S.EMERGENCY_STOP}), S.STOP, _stopped,
        "v < v_stopped (\"stopped\", whatever the threat)", "stopped"),
    Row(frozenset({S.EMERGENCY_STOP}), S.DECELERATION, _moving_threat_over,
        "moving and the threat is over",
        "threat over: required deceleration below a_emergency_exit and the gap opening"),
    Row(frozenset({S.STOP}), S.ACCELERATION, _start, "v_target > v_start and no threat",
        "target speed above v_start"),
    Row(_DRIVING, S.STOP, _stop, "v < v_stopped and v_target <= v_start",
        "stopped with no target speed to start"),
    Row(frozenset({S.DECELERATION, S.SPEED_KEEPING}), S.ACCELERATION, _guard(_speed_up),
        "speed up (A)", "target speed above the speed or the plan accelerates"),
    Row(frozenset({S.ACCELERATION, S.SPEED_KEEPING}), S.DECELERATION, _guard(_slow_down),
        "slow down (D)", "target speed below the speed or the plan decelerates"),
    Row(frozenset({S.ACCELERATION, S.DECELERATION}), S.SPEED_KEEPING, _guard(_on_target),
        "on target", "speed on target and the plan steady"),
))
EDGES = TABLE.edges  # every (from, to) pair the table allows


def transition(state: ControlState, x: ControlInput,
               p: ControlParams) -> Transition[ControlState] | None:
    """The change of state for input `x`, or None to stay (`TABLE`)."""
    return next_state(TABLE, state, x, p)


if __name__ == "__main__":  # print the table for the module doc
    print(render(TABLE))
