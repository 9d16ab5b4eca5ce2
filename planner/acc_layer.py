"""The ACC / event layer in the planner: the mode FSM (`planner.fsm.acc`) fed from the map,
the events and the lead track, and the mode's law (`planner.acc_control`) giving the target
speed [m/s] and feed-forward acceleration [m/s^2].

Per tick:

1. the lead's bumper gap is carried from its track's time t_track to now with the relative
   speed, ``d_now = d + (V_l - v) (t - t_track)`` (tracks are one sensor period old);
   V_GPS is the posted limit at the front bumper, V_s the set speed (ACC is on while
   V_s > 0);
2. the FSM steps once;
3. the mode's law gives the reference: ACC_OFF 0; CRUISE and SPEED_LIMIT the speed plan;
   TRAIL and BRAKE their laws behind the lead; OFF_RAMP the speed plan (the ramp's limit
   is a posting); STOP_SIGN, PEDESTRIAN, RED_LIGHT and YIELD a stop at the events' stop
   point; SPEED_BUMP the pass speed at the bump; FLAT down at ``a_flat_plan`` to
   ``v_pull_over`` while the car pulls over, then to a stop on the shoulder. A vehicle
   ahead still counts in an event mode: the reference is the lower of the event's law and
   the trail law behind it. The plan's `SpeedSource` is the law's where it lowers the
   speed plan (FLAT's always), the plan's own otherwise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from planner.acc_control import (
    AccControlParams,
    EasedBrake,
    brake_cap,
    braking_need,
    pass_speed,
    stop_speed,
    trail,
)
from planner.events import Events
from planner.fsm.acc import AccInput, AccMode, AccParams, gaps, transition
from planner.fsm.machine import Machine, StateChange
from planner.messages import Lead, SpeedSource
from planner.speed import PlannedSpeed, SpeedRef

NO_EVENTS = Events()
STOP_LAWS = frozenset({AccMode.STOP_SIGN, AccMode.PEDESTRIAN, AccMode.RED_LIGHT,
                       AccMode.YIELD})  # a stop at `Events.stop_distance`
EVENT_LAWS = frozenset({AccMode.OFF_RAMP, AccMode.SPEED_BUMP, AccMode.FLAT}) | STOP_LAWS


@dataclass(frozen=True, slots=True)
class AccLayerParams:
    modes: AccParams = field(default_factory=AccParams)  # the mode FSM's gaps
    control: AccControlParams = field(default_factory=AccControlParams)  # the modes' laws


@dataclass(frozen=True, slots=True)
class AccOutput:
    """The ACC / event layer's result for one tick."""

    speed: PlannedSpeed  # the reference after the mode's law
    lead_gap: float  # [m] the lead's gap carried to now (+inf: no lead)


class AccLayer:
    """Mode and controller state of the ACC / event layer for one run."""

    def __init__(self, params: AccLayerParams | None = None) -> None:
        self.params = params if params is not None else AccLayerParams()
        self.machine = Machine("acc", AccMode.ACC_OFF)
        self._brake = EasedBrake()
        self._flat: float | None = None  # [m/s] FLAT's ramped reference

    @property
    def mode(self) -> AccMode:
        return self.machine.state

    def update(self, t: float, dt: float, v: float, set_speed: float, limit: float,
               plan: PlannedSpeed, lead: Lead | None, driver_gap: float | None = None,
               events: Events = NO_EVENTS) -> tuple[AccOutput, tuple[StateChange, ...]]:
        """The speed reference now and the mode change made, if any.

        `t` now and `dt` since the last tick [s]; `v` ego speed, `set_speed` (V_s, 0: ACC
        off), `limit` the posted limit at the front bumper (V_GPS) [m/s]; `plan` the speed
        plan so far (the map's, after the driver's pedal); `lead` from its track; `events`
        the events now. `driver_gap` [m]: the driver's pedal overrides, and TRAIL and BRAKE
        may close up to d_min + this instead of d_des."""
        d, v_l = (lead.gap + (lead.speed - v) * max(t - lead.t, 0.0), lead.speed) \
            if lead is not None else (math.inf, math.inf)
        x = AccInput(acc_on=set_speed > 0.0, v=v, v_s=set_speed, v_gps=limit, d=d, v_l=v_l,
                     events=events.active)
        changes = self.machine.apply(t, transition(self.mode, x, self.params.modes))
        if self.mode in EVENT_LAWS:
            speed = self._event(x, dt, plan, events)
        else:
            speed = self._control(x, dt, plan, driver_gap)
        return AccOutput(speed, d), changes

    def _event(self, x: AccInput, dt: float, planned: PlannedSpeed,
               events: Events) -> PlannedSpeed:
        """The event mode's law, never above the trail law behind a vehicle ahead."""
        c, m = self.params.control, self.params.modes
        plan = planned.ref
        self._brake.reset()
        if self.mode is AccMode.FLAT:  # down to a crawl until on the shoulder, then a stop
            floor = 0.0 if events.pulled_over else min(c.v_pull_over, plan.speed)
            self._flat = plan.speed if self._flat is None else self._flat
            self._flat = max(min(self._flat, x.v) - c.a_flat_plan * dt, floor)
            out = PlannedSpeed(SpeedRef(self._flat, -c.a_flat_plan if self._flat > floor
                                        else 0.0), SpeedSource.EVENT)
        elif self.mode is AccMode.SPEED_BUMP:
            v = pass_speed(events.bump_distance, events.bump_speed, plan.speed, c)
            braking = events.bump_speed < v < plan.speed  # on the braking curve
            ref = SpeedRef(v, -c.a_comf if braking else 0.0 if v < plan.speed else plan.accel)
            out = PlannedSpeed(ref, SpeedSource.EVENT if v < plan.speed else planned.source)
        elif self.mode in STOP_LAWS:
            v = stop_speed(events.stop_distance, plan.speed, c)
            ref = SpeedRef(v, -c.a_comf if 0.0 < v < plan.speed else 0.0)
            out = PlannedSpeed(ref, SpeedSource.EVENT if v < plan.speed else planned.source)
        else:
            out = planned
        if math.isfinite(x.d):
            following = trail(plan.speed, x.d, gaps(x.v, x.v_l, m).d_des, x.v_l, m.d0, c)
            if following.speed < out.ref.speed:
                return PlannedSpeed(following, SpeedSource.FOLLOWING)
        return out

    def _control(self, x: AccInput, dt: float, planned: PlannedSpeed,
                 driver_gap: float | None) -> PlannedSpeed:
        c, m = self.params.control, self.params.modes
        plan = planned.ref
        if self.mode in (AccMode.BRAKE, AccMode.TRAIL):
            g = gaps(x.v, x.v_l, m)
            d_des = g.d_des if driver_gap is None else min(g.d_des, g.d_min + driver_gap)
            following = trail(plan.speed, x.d, d_des, x.v_l, m.d0, c)
        if self.mode is AccMode.BRAKE:
            need = braking_need(x.v, following.speed, x.d, c)
            ref = self._brake.step(x.v, need, dt, c, cap=brake_cap(x.v, x.v_l, x.d, c))
            return PlannedSpeed(ref, SpeedSource.FOLLOWING) if ref.speed < plan.speed \
                else planned
        self._brake.reset()
        if self.mode is AccMode.TRAIL:
            source = SpeedSource.FOLLOWING if following.speed < plan.speed else planned.source
            return PlannedSpeed(following, source)
        if self.mode is AccMode.ACC_OFF:
            return PlannedSpeed(SpeedRef(0.0, 0.0), SpeedSource.SET_SPEED)
        return planned
