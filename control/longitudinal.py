"""Speed control: feed-forward acceleration plus a speed PID, clamped and jerk limited.

Input per tick: the plan's target speed [m/s] and feed-forward acceleration [m/s^2], the
measured forward speed [m/s] and dt [s]. Output: a `SpeedCommand`, the acceleration request
[m/s^2] along the car's x axis and whether the car holds at a stop.

Steps of `SpeedController.update`:

1. Hold guard: when the target speed is at most ``stop_target_speed``, the plan asks for
   no acceleration and the car is slower than ``standstill_speed``, the car holds at a
   stop: the PID is reset (no windup while parked) and the desired request is
   -``hold_decel``, flagged ``hold`` so that actuation applies brake only.
2. Otherwise desired = target_accel (the planner's feed-forward) + PID(target_speed - speed).
   Conditional integration (anti-windup on top of the PID's clamp): the integrator runs only
   within |error| <= ``integration_band`` (a large speed step would charge it on the way up
   and overshoot), and is frozen while the previous request was cut by the limits in the
   direction the error pushes. Stall: once the request has been at least ``stall_rise`` for
   ``stall_delay`` with the car still below ``stall_speed`` and its target (held back by a
   speed bump's face, a kerb), the integrator runs whatever the error, as a driver presses
   on until the car moves; a car pulling away passes ``stall_speed`` well within
   ``stall_delay``. The stall test reads the request and the time, not the rise of the
   estimated speed, which lags and is noisy and would take a pull-away for a stall.
3. Clamp to [-``max_decel``, ``max_accel``] (ICCAS 2020 drives with at most 5 m/s^2).
   Comfort envelope (ISO 15622 / ISO 22179: an ACC decelerates at most 3.5 m/s^2 over 2 s,
   and its deceleration rises at most at 2.5 m/s^3 over 1 s): while the plan is
   comfortable, its feed-forward no harder than -``comfort_plan``, the request is also
   kept above -``comfort_decel`` and its deceleration rises at most at ``comfort_jerk``.
   The plan's deceleration is the planner's to choose (its laws plan at most
   ``comfort_plan`` unless no comfortable stop is left, `planner.acc_control`); the
   envelope keeps the PID's share within comfort too, so that a step in the target speed
   does not become a jolt. A car holding at a stop is at rest: no envelope. A plan asking
   for more than ``comfort_plan`` but no more than ``iso_plan`` (no comfortable stop left,
   but one within ISO's limits) gets ISO's own envelope: floor -``iso_decel``, rise at most
   ``iso_jerk``. A plan asking for more is urgent: the envelope is off and the actuator
   limits below apply. ISO judges the rise as an average over ``jerk_window`` (1 s): an
   envelope also keeps the deceleration at most its jerk times ``jerk_window`` above the
   request ``jerk_window`` ago (holding it, never releasing it, where an urgent rise just
   before took more): without it, an urgent plan that built 2.5 m/s^2 in 0.25 s and then
   eased back into ISO's envelope went on rising at its jerk, 2.8 m/s^3 over the second.
   While the envelope was on throughout the window, the per-step rise already keeps it.
4. Jerk limit: the request moves by at most ``max_jerk`` dt per step (in a comfortable
   plan, a request at or below 0 falls by at most ``comfort_jerk`` dt, ``iso_jerk`` dt in
   one within ISO's limits: the deceleration
   rises at the comfort jerk, while an acceleration is still taken back at once). ``max_jerk`` is an
   actuator guard: it keeps torque steps and PID noise off the drivetrain while letting
   hard braking reach ``max_decel`` within a fraction of a second.

The first step after `reset()` ramps from 0 m/s^2.

Emergency stop (``emergency``: the planner's control FSM in EMERGENCY_STOP): the PID is reset
and steps 1-4 are skipped. The request falls towards the plan's feed-forward (its emergency
deceleration, `planner.limits.A_EMERGENCY`, which may exceed ``max_decel``) by at most
``emergency_jerk`` dt per step (the brake's own rise rate), never below it; ``hold`` is set
below ``standstill_speed``. Afterwards the jerk limit takes the request on from where it is.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

from control.pid import Pid, PidParams

__all__ = ["SpeedCommand", "SpeedController", "SpeedParams"]

TAU_V = 0.8  # [s] time constant of the speed error (P action)
KP_V = 1.0 / TAU_V  # [1/s]
TAU_I = 4.0  # [s] integral time (Ti): the I action matches the P action after TAU_I
KI_V = KP_V / TAU_I  # [1/s^2]


@dataclass(frozen=True, slots=True)
class SpeedParams:
    """Gains and limits of the speed loop."""

    kp: float = KP_V  # [1/s] (m/s^2 per m/s of speed error)
    ki: float = KI_V  # [1/s^2]
    kd: float = 0.0  # [-] (m/s^2 per m/s^2 of error rate)
    integral_limit: float = 1.0  # [m/s^2] |integral term| clamp (grades, drag-model error)
    integration_band: float = 1.0  # [m/s] the integrator only runs within this speed error
    stall_speed: float = 0.5  # [m/s] ... or when slower than this, below the target,
    stall_rise: float = 0.2  # [m/s^2] asked for at least this much acceleration
    stall_delay: float = 0.5  # [s] for this long: held back (a bump, a kerb); longer than a
    #   pull-away needs to pass stall_speed
    derivative_tau: float = 0.2  # [s] low-pass on the error derivative
    max_accel: float = 5.0  # [m/s^2] ICCAS 2020: max 5 m/s^2
    max_decel: float = 6.0  # [m/s^2] positive number, braking limit
    max_jerk: float = 10.0  # [m/s^3] rate limit on the request (see module doc)
    stop_target_speed: float = 0.05  # [m/s] a target at or below this means "stop"
    standstill_speed: float = 0.3  # [m/s] below this (with a stop target) the car holds
    hold_decel: float = 3.0  # [m/s^2] positive, the request while holding (brake only)
    emergency_jerk: float = 40.0  # [m/s^3] the emergency request's rise rate (the brake's)
    comfort_plan: float = 3.0  # [m/s^2] a plan braking no harder than this is comfortable
    #   (`planner.limits.A_COMF_MAX`)
    comfort_decel: float = 3.2  # [m/s^2] in a comfortable plan, the request's floor (under
    #   ISO 15622's 3.5 m/s^2)
    comfort_jerk: float = 2.0  # [m/s^3] in a comfortable plan, the most the deceleration
    #   rises per second (under ISO 15622's 2.5 m/s^3; `planner.limits.J_COMF`)
    iso_plan: float = 3.45  # [m/s^2] a plan braking no harder than this is within ISO's
    #   limits (`planner.limits.A_ISO_MAX`)
    iso_decel: float = 3.45  # [m/s^2] in such a plan, the request's floor (under ISO 15622's
    #   3.5 m/s^2)
    iso_jerk: float = 2.4  # [m/s^3] in such a plan, the most the deceleration rises per
    #   second (under ISO 15622's 2.5 m/s^3; `planner.limits.J_ISO_PLAN`)
    jerk_window: float = 1.0  # [s] an envelope's rise, jerk times this at most over this
    #   span (ISO 15622's average of the rise of deceleration)

    @property
    def pid(self) -> PidParams:
        """The speed PID: error [m/s], output [m/s^2]."""
        return PidParams.of(self)


@dataclass(frozen=True, slots=True)
class SpeedCommand:
    """The longitudinal request of one tick."""

    accel: float  # [m/s^2] along the car's x axis, clamped and jerk limited
    hold: bool  # the car is holding at a stop: brake only, no drive torque


class SpeedController:
    """Speed PID with feed-forward, accel clamp, jerk limit and standstill hold."""

    def __init__(self, params: SpeedParams | None = None) -> None:
        self.params = SpeedParams() if params is None else params
        self._pid = Pid(self.params.pid)
        self._accel = 0.0  # [m/s^2] previous request, for the jerk limit
        self._excess = 0.0  # [m/s^2] previous desired minus limited request
        self._pressing = 0.0  # [s] asked to speed up, still below stall_speed (stall test)
        self._past = RequestWindow(self.params.jerk_window)  # the requests of the window

    def reset(self) -> None:
        """Clear the PID and start the jerk limit from 0 m/s^2."""
        self._pid.reset()
        self._accel = 0.0
        self._excess = 0.0
        self._pressing = 0.0
        self._past = RequestWindow(self.params.jerk_window)

    def _envelope(self, target_accel: float, hold: bool) -> tuple[float, float] | None:
        """(floor [m/s^2], jerk [m/s^3]) of the comfort envelope for a plan whose
        feed-forward is `target_accel` [m/s^2] (module doc, step 3); None: urgent, or at
        rest (`hold`)."""
        p = self.params
        if hold or target_accel < -p.iso_plan:
            return None
        if target_accel >= -p.comfort_plan:
            return p.comfort_decel, p.comfort_jerk
        return p.iso_decel, p.iso_jerk

    def update(
        self, target_speed: float, target_accel: float, speed: float, dt: float,
        *, emergency: bool = False,
    ) -> SpeedCommand:
        """One step: target_speed [m/s], target_accel [m/s^2] feed-forward, speed [m/s]
        measured forward speed, dt [s] -> the acceleration request. `emergency`: brake
        towards `target_accel` (the plan's emergency deceleration) at `emergency_jerk`
        (module doc)."""
        p = self.params
        if emergency:
            self._pid.reset()
            step = p.emergency_jerk * dt
            accel = max(self._accel - step, target_accel)
            self._accel, self._excess = accel, 0.0
            self._past.push(dt, accel)
            return SpeedCommand(accel=accel, hold=speed < p.standstill_speed)
        stop_requested = target_speed <= p.stop_target_speed and target_accel <= 0.0
        at_standstill = speed < p.standstill_speed
        hold = stop_requested and at_standstill
        if hold:
            self._pid.reset()
            desired = -p.hold_decel
        else:
            error = target_speed - speed
            stalled = error > 0.0 and self._pressing >= p.stall_delay
            integrate = self._excess * error <= 0.0 and (abs(error) <= p.integration_band
                                                         or stalled)
            desired = target_accel + self._pid.update(error, dt, integrate=integrate)
        envelope = self._envelope(target_accel, hold)
        floor = p.max_decel if envelope is None else envelope[0]
        clamped = min(max(desired, -floor), p.max_accel)
        max_step = p.max_jerk * dt
        low = self._accel - max_step  # the braking part of a drop, at the envelope's jerk:
        if envelope is not None:
            low = max(low, min(self._accel, 0.0) - envelope[1] * dt,
                      min(self._accel, min(self._past.start(dt), 0.0)
                          - envelope[1] * p.jerk_window))
        accel = min(max(clamped, low), self._accel + max_step)
        self._past.push(dt, accel)
        self._excess = desired - accel
        pressing = accel >= p.stall_rise and speed < p.stall_speed and not hold
        self._pressing = self._pressing + dt if pressing else 0.0
        self._accel = accel
        return SpeedCommand(accel=accel, hold=hold)


class RequestWindow:
    """The requests [m/s^2] of the last `span` [s], one per step, for the envelope's rise
    over ISO's window: `start` is the request at the window's start."""

    def __init__(self, span: float) -> None:
        self.span = span  # [s]
        self._t = 0.0  # [s] since the first step
        self._steps: deque[tuple[float, float]] = deque([(0.0, 0.0)])  # (time [s], request)

    def start(self, dt: float) -> float:
        """[m/s^2] the request at the start of the window that ends dt [s] from the last
        step: the newest at least `span` before then (the first, 0 after a reset, while the
        window is not yet full)."""
        self._drop(self._t + dt - self.span)
        return self._steps[0][1]

    def push(self, dt: float, accel: float) -> None:
        """Record the request `accel` [m/s^2] of the step dt [s] after the last (keeping
        only the steps a window from now on reads: at most one per step of the span)."""
        self._t += dt
        self._steps.append((self._t, accel))
        self._drop(self._t - self.span)

    def __len__(self) -> int:
        return len(self._steps)

    def _drop(self, end: float) -> None:
        """Drop the steps older than the newest at or before `end` [s]."""
        steps = self._steps
        while len(steps) > 1 and steps[1][0] <= end:
            steps.popleft()
