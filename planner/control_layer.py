"""The control FSM in the planner (`planner.fsm.control`): the threat from the lead and the
control action that holds.

Per tick the lead's bumper gap [m] (carried from its track's time to now at the closing
speed), speed [m/s] and acceleration [m/s^2] (`planner.lead.LeadAccel`) give the
deceleration needed to stop ``stop_gap`` short of it and the time to collision
(`planner.fsm.control`); with the speed target after the ACC layer, the FSM steps once.

The time to collision and the gap's carry take the lead's signed velocity along the ego's
direction (`Lead.along`): an oncoming car closes at the two speeds' sum, so at equal speeds
its time to collision is half the gap over the ego's speed. The deceleration needed takes
it as standing (`Lead.speed`, >= 0): braking cannot shed an oncoming car's speed, only the
ego's, and a stop before it arrives would be planned on a collision course the other car
may still leave (a head-on at 70 km/h each: a threat 113 m, 2.9 s, ahead), so the time to
collision decides (`ttc_emergency`), and the brake reduces the impact speed.

In EMERGENCY_STOP the plan asks for ``emergency_decel`` down to a standstill, whatever the
ACC's target: the speed loop brakes at once at the actuator's limits
(`control.longitudinal`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from planner.fsm.control import (
    ControlInput,
    ControlParams,
    ControlState,
    required_deceleration,
    time_to_collision,
    transition,
)
from planner.fsm.machine import Machine, StateChange
from planner.limits import A_EMERGENCY
from planner.messages import Lead


@dataclass(frozen=True, slots=True)
class ControlLayerParams:
    fsm: ControlParams = field(default_factory=ControlParams)  # the C-FSM's thresholds
    emergency_decel: float = A_EMERGENCY  # [m/s^2] the emergency stop's deceleration
    stop_gap: float = 1.0  # [m] the gap the required deceleration keeps to the lead


@dataclass(frozen=True, slots=True)
class ControlOutput:
    state: ControlState  # the control action that holds
    a_required: float  # [m/s^2] to stop `stop_gap` short of the lead
    ttc: float  # [s] time to collision with the lead (+inf: none)

    @property
    def emergency(self) -> bool:
        """Whether the state is EMERGENCY_STOP."""
        return self.state is ControlState.EMERGENCY_STOP


class ControlLayer:
    """Control state of one run."""

    def __init__(self, params: ControlLayerParams | None = None) -> None:
        self.params = params if params is not None else ControlLayerParams()
        self.machine = Machine("control", ControlState.STOP)

    @property
    def decel(self) -> float:
        """[m/s^2] the emergency stop's deceleration (> 0)."""
        return self.params.emergency_decel

    def update(self, t: float, v: float, v_target: float, a_target: float,
               lead: Lead | None, lead_accel: float) -> tuple[ControlOutput,
                                                               tuple[StateChange, ...]]:
        """Step at time `t` [s] with the ego speed `v`, the target `v_target` [m/s] and
        feed-forward `a_target` [m/s^2] after the ACC layer; `lead` from its track,
        `lead_accel` [m/s^2] its acceleration (signed)."""
        a_req, ttc = 0.0, math.inf
        if lead is not None:
            gap = lead_gap_now(lead, t, v)
            a_req = required_deceleration(v, gap, lead.speed, lead_accel, self.params.stop_gap)
            ttc = time_to_collision(gap, v, lead.along)
        x = ControlInput(v=v, v_target=v_target, a_target=a_target, a_required=a_req, ttc=ttc)
        changes = self.machine.apply(t, transition(self.machine.state, x, self.params.fsm))
        return ControlOutput(self.machine.state, a_req, ttc), changes


def lead_gap_now(lead: Lead, t: float, v: float) -> float:
    """[m] the bumper gap to `lead` at time `t` [s], the ego at `v` [m/s]: its track's gap
    carried over the track's age at the closing speed (signed: an oncoming car's adds)."""
    return lead.gap + (lead.along - v) * max(t - lead.t, 0.0)
