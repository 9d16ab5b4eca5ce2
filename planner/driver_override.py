"""The driver's accelerator pedal under the stack: a speed limiter (ICCAS 2020's external
disturbance, "an external acceleration command issued by a gas pedal or a control device").

The car is drive-by-wire: the pedal position p in [0, 1] is a vehicle signal the stack reads
with the odometry, and it adds no torque by itself. It asks for an acceleration
``a_drv = p * a_full`` [m/s^2]. Above ``threshold`` the driver overrides the cruise set
speed, and the reference [m/s] and feed-forward [m/s^2] become

    v_ref = min(v_cap, v + a_drv * horizon)
    a_ff  = min(a_drv, max(v_cap - v, 0) / tau)      (a_ff = the envelope's while it brakes)

where v_cap is the map's speed envelope with the set speed raised to the vehicle's maximum
(the posted limit, the curves, the braking curves to lower limits ahead): the pedal raises
the speed up to the limit and never past it, and the feed-forward fades over the last
``tau * a_drv`` m/s so that the car reaches the limit without overshoot. The ACC layer keeps
its modes and laws on top of this reference, with the driver's shorter gap: it lets the
pedal close up on a lead to ``d_min + gap_margin``, never to d_min (`planner.acc_layer`;
while the car closes, its approach ends at d_min of the car's own speed + gap_margin, so
that braking to the lead's speed never takes the gap under d_min on the way).
When the pedal is released above the plan's speed, the reference comes back down to the
plan at ``a_release``, not in a step.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from planner.messages import SpeedSource
from planner.speed import BINDING_SOURCE, PlannedSpeed, SpeedRef
from planner.speed_planning import SpeedTarget


@dataclass(frozen=True, slots=True)
class OverrideParams:
    threshold: float = 0.05  # [-] pedal positions above this override the set speed
    a_full: float = 3.0  # [m/s^2] the acceleration the full pedal asks for (about a mid-size
    #   car's full-throttle acceleration at town speeds)
    horizon: float = 0.5  # [s] the reference leads the speed by a_drv * horizon
    tau: float = 1.0  # [s] the feed-forward fades within a_drv * tau of the limit
    gap_margin: float = 2.0  # [m] following, the driver may close up to d_min + this
    a_release: float = 1.0  # [m/s^2] after the pedal, back down to the plan at this


def overriding(pedal: float, p: OverrideParams) -> bool:
    """Whether pedal position `pedal` [-] overrides the set speed."""
    return pedal > p.threshold


def override_reference(pedal: float, v: float, cap: SpeedTarget,
                       p: OverrideParams) -> PlannedSpeed:
    """The speed reference for pedal position `pedal` at speed `v` [m/s] under the envelope
    `cap` (the speed plan at the vehicle's maximum set speed): the pedal's, or the
    envelope's where it binds."""
    a_drv = min(max(pedal, 0.0), 1.0) * p.a_full
    asked = v + a_drv * p.horizon
    speed = min(cap.speed, asked)
    source = BINDING_SOURCE[cap.binding] if cap.speed <= asked else SpeedSource.PEDAL
    if cap.accel < 0.0:
        return PlannedSpeed(SpeedRef(speed, cap.accel), source)
    return PlannedSpeed(SpeedRef(speed, min(a_drv, max(cap.speed - v, 0.0) / p.tau)), source)


class DriverOverride:
    """The pedal's reference and the ramp back after it, for one run."""

    def __init__(self, params: OverrideParams | None = None) -> None:
        self.params = params if params is not None else OverrideParams()
        self._release: float | None = None  # [m/s] the ramp's speed after a release

    def update(self, pedal: float, v: float, plan: PlannedSpeed,
               cap: Callable[[], SpeedTarget], dt: float) -> tuple[PlannedSpeed, bool]:
        """The reference in place of `plan` (the map's at the set speed) and whether the
        driver overrides now, for pedal position `pedal` [-], speed `v` [m/s] and `dt` [s]
        since the last tick; `cap()` gives the envelope at the vehicle's maximum speed."""
        p = self.params
        if overriding(pedal, p):
            ref = override_reference(pedal, v, cap(), p)
            self._release = max(ref.ref.speed, v)
            return ref, True
        if self._release is None:
            return plan, False
        self._release -= p.a_release * dt
        if self._release <= plan.ref.speed:
            self._release = None
            return plan, False
        return PlannedSpeed(SpeedRef(self._release, -p.a_release), SpeedSource.PEDAL), False
