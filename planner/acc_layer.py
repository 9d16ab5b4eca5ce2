"""The ACC / event layer in the planner: the mode FSM (`planner.acc`) fed from the map and
the lead track, and the mode's controller (`planner.acc_control`) giving the target speed.

Per tick: the lead's gap is carried from its track's time to now with the relative speed
(``d_now = d + (V_l - v) (t - t_track)``: tracks are one sensor period old); V_GPS is the
posted limit at the front bumper; V_s the set speed. The FSM steps once; the mode's law gives
the speed reference, never above the map's plan. Events (ramp, pedestrian, bump, stop sign,
flat) are not detected yet: their modes keep the map's plan (the DECS route, issue D).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from planner.acc import AccInput, AccMode, AccParams, gaps, transition
from planner.acc_control import (
    AccControlParams,
    EasedBrake,
    SpeedRef,
    brake_cap,
    braking_need,
    trail,
)
from planner.messages import Lead, StateChange


@dataclass(frozen=True, slots=True)
class AccLayerParams:
    modes: AccParams = field(default_factory=AccParams)
    control: AccControlParams = field(default_factory=AccControlParams)


class AccLayer:
    """Mode and controller state of the ACC / event layer for one run."""

    def __init__(self, params: AccLayerParams | None = None) -> None:
        self.params = params if params is not None else AccLayerParams()
        self.mode = AccMode.ACC_OFF
        self._brake = EasedBrake()
        self.lead_gap = float("inf")  # [m] the last update's lead gap, carried to its time

    def update(self, t: float, dt: float, v: float, set_speed: float, limit: float,
               plan: SpeedRef, lead: Lead | None, driver_gap: float | None = None,
               ) -> tuple[SpeedRef, tuple[StateChange, ...]]:
        """The speed reference now [m/s, m/s^2] and the mode change made, if any.

        `v` ego speed, `limit` the posted limit at the front bumper (V_GPS), `plan` the map's
        speed plan (set speed, limits, curves) [m/s]. `driver_gap` [m]: the driver's pedal
        overrides, and the trail law may close up to d_min + this instead of d_des."""
        d, v_l = (lead.gap + (lead.speed - v) * max(t - lead.t, 0.0), lead.speed) \
            if lead is not None else (float("inf"), float("inf"))
        self.lead_gap = d
        x = AccInput(acc_on=set_speed > 0.0, v=v, v_s=set_speed, v_gps=limit, d=d, v_l=v_l)
        changes: tuple[StateChange, ...] = ()
        change = transition(self.mode, x, self.params.modes)
        if change is not None:
            changes = (StateChange(t, "acc", self.mode.value, change.to.value, change.reason),)
            self.mode = change.to
        return self._control(x, dt, plan, driver_gap), changes

    def _control(self, x: AccInput, dt: float, plan: SpeedRef,
                 driver_gap: float | None) -> SpeedRef:
        c, m = self.params.control, self.params.modes
        if self.mode in (AccMode.BRAKE, AccMode.TRAIL):
            g = gaps(x.v, x.v_l, m)
            d_des = g.d_des if driver_gap is None else min(g.d_des, g.d_min + driver_gap)
            following = trail(plan.speed, x.d, d_des, x.v_l, m.d0, c)
        if self.mode is AccMode.BRAKE:
            need = braking_need(x.v, following.speed, x.d, c)
            ref = self._brake.step(x.v, need, dt, c, cap=brake_cap(x.v, x.v_l, x.d, c))
            return ref if ref.speed < plan.speed else plan
        self._brake.reset()
        if self.mode is AccMode.TRAIL:
            return following
        if self.mode is AccMode.ACC_OFF:
            return SpeedRef(0.0, 0.0)
        return plan
