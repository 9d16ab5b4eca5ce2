"""A constant-time-gap ACC in place of the bundled planner's longitudinal law.

The bundled planner still finds the path, keeps the lane and answers signs, lights and
hazards; behind a lead its target speed is replaced by this law's when that is lower:

    d_des = d_0 + T v                                  [m] the gap wanted
    a     = k_gap (d - d_des) + k_speed (v_lead - v)   [m/s^2], within [A_MIN, A_MAX]
    v_target = max(0, v + a HORIZON)                   [m/s]

Run it with ``avsim run sudden_stop --planner examples/stacks/time_gap_acc.py:make``.
"""

from __future__ import annotations

from dataclasses import replace

from avsim.stack import Plan, PlannerInput, StackContext, bundled

__version__ = "1.0"

TIME_GAP = 1.8  # [s] T
STANDSTILL = 5.0  # [m] d_0
K_GAP = 0.2  # [1/s]
K_SPEED = 0.6  # [1/s]
A_MIN, A_MAX = -5.0, 2.0  # [m/s^2]
HORIZON = 0.5  # [s] the acceleration's reach into the target speed


class TimeGapAcc:
    """The bundled planner, its target speed behind a lead taken from the law above."""

    def __init__(self, ctx: StackContext) -> None:
        self.inner = bundled.planner(ctx)
        self.ticks_in_force = 0  # control ticks at which this law set the target

    def update(self, inp: PlannerInput) -> Plan:
        plan = self.inner.update(inp)
        if plan.lead is None:
            return plan
        v = inp.ego.speed
        wanted = STANDSTILL + TIME_GAP * v
        accel = K_GAP * (plan.lead.gap - wanted) + K_SPEED * (plan.lead.speed - v)
        accel = min(max(accel, A_MIN), A_MAX)
        target = max(0.0, v + accel * HORIZON)
        if target >= plan.target_speed:
            return plan
        self.ticks_in_force += 1
        return replace(plan, target_speed=target, target_accel=accel)


def make(ctx: StackContext) -> TimeGapAcc:
    return TimeGapAcc(ctx)
