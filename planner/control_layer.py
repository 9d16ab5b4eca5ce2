"""The control FSM in the planner (`planner.fsm.control`): the threat from the lead and the
control action that holds.

Per tick the lead's bumper gap [m] (carried to now), speed [m/s] and acceleration [m/s^2]
(`planner.lead.LeadAccel`) give the deceleration needed to stop ``stop_gap`` short of it
and the time to collision (`planner.fsm.control`); with the speed target after the ACC
layer, the FSM steps once. In EMERGENCY_STOP the plan asks for
``emergency_decel`` down to a standstill, whatever the ACC's target: the speed loop brakes
at once at the actuator's limits (`control.longitudinal`).
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

    def update(self, t: float, v: float, v_target: float, a_target: float, gap: float,
               lead: Lead | None, lead_accel: float) -> tuple[ControlOutput,
                                                               tuple[StateChange, ...]]:
        """Step at time `t` [s] with the ego speed `v`, the target `v_target` [m/s] and
        feed-forward `a_target` [m/s^2] after the ACC layer; `gap` [m] to the lead now,
        `lead_accel` [m/s^2] its acceleration (signed)."""
        a_req, ttc = 0.0, math.inf
        if lead is not None and math.isfinite(gap):
            a_req = required_deceleration(v, gap, lead.speed, lead_accel, self.params.stop_gap)
            ttc = time_to_collision(gap, v, lead.speed)
        x = ControlInput(v=v, v_target=v_target, a_target=a_target, a_required=a_req, ttc=ttc)
        changes = self.machine.apply(t, transition(self.machine.state, x, self.params.fsm))
        return ControlOutput(self.machine.state, a_req, ttc), changes
