"""The ACC / event layer in the planner: the mode FSM (`planner.fsm.acc`) fed from the map,
the events and the lead track, and the mode's law (`planner.acc_control`) giving the target
speed [m/s] and feed-forward acceleration [m/s^2].

Per tick:

1. the lead's bumper gap is carried from its track's time t_track to now with the relative
   speed, ``d_now = d + (V_l - v) (t - t_track)`` (tracks are one sensor period old);
   V_GPS is the posted limit at the front bumper, V_s the set speed (ACC is on while
   V_s > 0); the least deceleration that still stops the closing on the lead
   (`planner.acc_control.need`, from the deceleration the car brakes at now), whether it
   leaves a comfortable stop (and with the FSM's hysteresis to spare), the time to
   collision, and whether a lead was lost within the FSM's ``lead_hold``;
2. the FSM steps once;
3. the mode's law gives the reference: ACC_OFF 0; CRUISE and SPEED_LIMIT the speed plan
   (for the first ``t_acquire`` after the ACC engages, the car's speed at most: no speeding
   up before the sensors' first confirmed tracks);
   TRAIL and BRAKE their laws behind the lead (TRAIL with its lead lost within the FSM's
   ``lead_hold``: the car's own speed, at most the plan's; the plan would speed it up into
   a lead whose track dropped for a moment, closing on it at 5 m/s when it was found again
   and under UN R157's d_min); OFF_RAMP the speed plan (the ramp's limit
   is a posting); STOP_SIGN, PEDESTRIAN, RED_LIGHT and YIELD a stop at the events' stop
   point; SPEED_BUMP the pass speed at the bump; FLAT down at ``a_flat_plan`` to
   ``v_pull_over`` while the car pulls over, then to a stop on the shoulder. Each law
   behind a lead and each stop or pass point goes through the approach
   (`planner.acc_control`: a planned constant deceleration within ISO 15622's comfort
   where the car is faster than the law). A vehicle ahead still counts in an event mode:
   the reference is the lower of the event's law and the trail law behind it. Lower is
   what the speed loop would ask less of the car on, ``a_ff + (v_ref - v) / tau_loop``
   (the minimum of the laws' outputs: a planned deceleration from the car's speed counts
   by its feed-forward, and binds even while the car is a ripple above the plan). The
   plan's `SpeedSource` is the law's where it lowers the speed plan (FLAT's always), the
   plan's own otherwise;
4. the deceleration the car brakes at is carried on from the reference's feed-forward
   (`planner.acc_control.BrakeModel`: it rises at the speed loop's comfort jerk).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from planner.acc_control import (
    AccControlParams,
    BrakeModel,
    bump,
    comfortable,
    follow,
    lead_speed_now,
    need,
    stop,
    trail,
    ttc,
)
from planner.events import Events
from planner.fsm.acc import AccInput, AccMode, AccParams, gaps, r157_min_gap, transition
from planner.fsm.machine import Machine, StateChange
from planner.messages import Lead, SpeedSource
from planner.speed import PlannedSpeed, SpeedRef

NO_EVENTS = Events()
STOP_LAWS = frozenset({AccMode.STOP_SIGN, AccMode.PEDESTRIAN, AccMode.RED_LIGHT,
                       AccMode.YIELD})  # a stop at `Events.stop_distance`
EVENT_LAWS = frozenset({AccMode.OFF_RAMP, AccMode.SPEED_BUMP, AccMode.FLAT}) | STOP_LAWS
ACQUIRING = frozenset({AccMode.CRUISE, AccMode.SPEED_LIMIT})  # hold for t_acquire (params)


@dataclass(frozen=True, slots=True)
class AccLayerParams:
    modes: AccParams = field(default_factory=AccParams)  # the mode FSM's gaps
    control: AccControlParams = field(default_factory=AccControlParams)  # the modes' laws
    t_acquire: float = 0.5  # [s] after the ACC engages, CRUISE and SPEED_LIMIT hold the
    #   car's speed (at most the plan's) this long: a vehicle ahead is a confirmed track
    #   only after the LiDAR's first scans (three at 10 Hz), and the car does not speed up
    #   towards its set speed before it could know the lane ahead is clear


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
        self._flat: float | None = None  # [m/s] FLAT's ramped reference
        self._braking = BrakeModel()  # the deceleration the car brakes at (`need`)
        self._lead_seen = -math.inf  # [s] when a lead was last seen
        self._a_lead = 0.0  # [m/s^2] the lead's acceleration this tick (signed)
        self._engaged: float | None = None  # [s] when the ACC last left ACC_OFF
        self._entered = False  # the lead entered the lane ahead (`planner.messages.Lead`)

    @property
    def mode(self) -> AccMode:
        return self.machine.state

    def update(self, t: float, dt: float, v: float, set_speed: float, limit: float,
               plan: PlannedSpeed, lead: Lead | None, driver_gap: float | None = None,
               events: Events = NO_EVENTS,
               lead_accel: float = 0.0) -> tuple[AccOutput, tuple[StateChange, ...]]:
        """The speed reference now and the mode change made, if any.

        `t` now and `dt` since the last tick [s]; `v` ego speed, `set_speed` (V_s, 0: ACC
        off), `limit` the posted limit at the front bumper (V_GPS) [m/s]; `plan` the speed
        plan so far (the map's, after the driver's pedal); `lead` from its track; `events`
        the events now. `driver_gap` [m]: the driver's pedal overrides, and TRAIL and BRAKE
        may close up to d_min + this instead of d_des. `lead_accel` [m/s^2]: the lead's
        acceleration, signed (`planner.lead.LeadAccel`)."""
        c = self.params.control
        self._a_lead = lead_accel if lead is not None else 0.0
        self._entered = lead is not None and lead.entered
        d, v_l = math.inf, math.inf
        if lead is not None:
            age = max(t - lead.t, 0.0)
            d = lead.gap + (lead.speed - v) * age
            v_l = lead_speed_now(lead.speed, self._a_lead, age, c)
        a_need = need(v, v_l, d, c, self._braking.a, self._a_lead)
        time_to_collision = ttc(v, v_l, d)
        self._lead_seen = t if lead is not None else self._lead_seen
        x = AccInput(acc_on=set_speed > 0.0, v=v, v_s=set_speed, v_gps=limit, d=d, v_l=v_l,
                     events=events.active, a_need=a_need, ttc=time_to_collision,
                     comfortable=comfortable(a_need, c),
                     relaxed=comfortable(a_need + self.params.modes.a_hysteresis, c),
                     lead_lost=lead is None and t - self._lead_seen <= self.params.modes.lead_hold)
        changes = self.machine.apply(t, transition(self.mode, x, self.params.modes))
        engaged = self.mode is not AccMode.ACC_OFF
        self._engaged = (self._engaged if self._engaged is not None else t) if engaged \
            else None
        if self.mode in EVENT_LAWS:
            speed = self._event(x, dt, plan, events)
        else:
            speed = self._control(x, dt, plan, driver_gap)
            since = t - self._engaged if self._engaged is not None else 0.0  # [s]
            if self.mode in ACQUIRING and since < self.params.t_acquire:
                speed = PlannedSpeed(SpeedRef(min(speed.ref.speed, v), 0.0), speed.source)
        self._braking.step(speed.ref.accel, dt, c)
        return AccOutput(speed, d), changes

    def _event(self, x: AccInput, dt: float, planned: PlannedSpeed,
               events: Events) -> PlannedSpeed:
        """The event mode's law, never above the trail law behind a vehicle ahead."""
        c = self.params.control
        plan = planned.ref
        if self.mode is AccMode.FLAT:  # down to a crawl until on the shoulder, then a stop
            floor = 0.0 if events.pulled_over else min(c.v_pull_over, plan.speed)
            self._flat = plan.speed if self._flat is None else self._flat
            self._flat = max(min(self._flat, x.v) - c.a_flat_plan * dt, floor)
            out = PlannedSpeed(SpeedRef(self._flat, -c.a_flat_plan if self._flat > floor
                                        else 0.0), SpeedSource.EVENT)
        elif self.mode is AccMode.SPEED_BUMP:
            ref = bump(events.bump_distance, events.bump_speed, x.v, plan.speed, dt, c,
                       self._braking.a)
            out = self._lower(planned, PlannedSpeed(ref, SpeedSource.EVENT), x.v)
        elif self.mode in STOP_LAWS:
            ref = stop(events.stop_distance, x.v, plan.speed, dt, c, self._braking.a)
            out = self._lower(planned, PlannedSpeed(ref, SpeedSource.EVENT), x.v)
        else:
            out = planned
        if math.isfinite(x.d):
            following = self._following(x, dt, plan, None)
            return self._lower(out, PlannedSpeed(following, SpeedSource.FOLLOWING), x.v)
        return out

    def _lower(self, planned: PlannedSpeed, law: PlannedSpeed, v: float) -> PlannedSpeed:
        """The minimum of two laws' outputs: `law` where the speed loop would ask less of
        the car on it than on `planned` at the speed v [m/s] (its request, feed-forward +
        (speed - v) / tau_loop: a planned deceleration from the speed counts by its
        feed-forward), else `planned`."""
        tau = self.params.control.tau_loop

        def request(ref: SpeedRef) -> float:
            return ref.accel + (ref.speed - v) / tau

        return law if request(law.ref) < request(planned.ref) else planned

    def _following(self, x: AccInput, dt: float, plan: SpeedRef,
                   driver_gap: float | None, a_min: float = 0.0) -> SpeedRef:
        """The trail law behind the lead (at d_min + `driver_gap` at most, while the driver
        overrides) through the approach (`planner.acc_control.follow`)."""
        c, m = self.params.control, self.params.modes
        g = gaps(x.v, x.v_l, m)
        d_des = g.d_des if driver_gap is None else min(g.d_des, g.d_min + driver_gap)
        slope = (g.d_des - gaps(max(x.v - 0.1, 0.0), x.v_l, m).d_des) / 0.1 \
            if driver_gap is None else 0.0  # [s] d(d_des)/dv
        law = trail(plan.speed, x.d, d_des, x.v_l, m.d0, c, self._a_lead, slope,
                    x.v - x.v_l)
        stopped = x.v_l < c.v_standstill
        rest = m.d0 + c.stop_band
        end = rest if stopped else gaps(x.v_l, x.v_l, m).d_des
        if driver_gap is not None and not stopped:  # d_min at the faster of the two: a
            end = min(end, r157_min_gap(max(x.v, x.v_l)) + driver_gap)  # closing car's
        return follow(x.v, law, x.d, x.v_l, end, dt, c, a_min, self._braking.a,
                      self._a_lead, rest, self._entered)

    def _control(self, x: AccInput, dt: float, planned: PlannedSpeed,
                 driver_gap: float | None) -> PlannedSpeed:
        c, m = self.params.control, self.params.modes
        plan = planned.ref
        if self.mode is AccMode.BRAKE:  # open a gap under d_min at up to a_open
            opening = c.a_open if x.d <= gaps(x.v, x.v_l, m).d_min else 0.0
            ref = self._following(x, dt, plan, driver_gap, opening)
            return self._lower(planned, PlannedSpeed(ref, SpeedSource.FOLLOWING), x.v)
        if self.mode is AccMode.TRAIL:
            following = self._following(x, dt, plan, driver_gap)
            if x.lead_lost:  # its track dropped for a moment: hold the speed, not the plan
                following = SpeedRef(min(plan.speed, x.v), 0.0)
            source = SpeedSource.FOLLOWING if following.speed < plan.speed else planned.source
            return PlannedSpeed(following, source)
        if self.mode is AccMode.ACC_OFF:
            return PlannedSpeed(SpeedRef(0.0, 0.0), SpeedSource.SET_SPEED)
        return planned
