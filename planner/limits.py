"""The decelerations the planner plans with, in one place [m/s^2, positive numbers].

Every parameter set of the planner that brakes takes its default from here, so that the
comfort and emergency limits are stated once:

- `A_COMF`: comfortable braking: approaches to lower limits, curves, stop lines,
  crossings and bumps, the ACC's d_max and trail law, the lane-lost ramp;
- `A_FIRM`: firm braking: the most the ACC's BRAKE mode plans short of an imminent
  collision, the yellow-light rule's and the junction commitment's "can still stop";
- `A_HARD`: hard braking: the most BRAKE plans when the time to collision is short;
  beyond it the control FSM calls an emergency;
- `A_FLAT`: the most a flat tyre's stop may plan (the DECS acceptance);
- `A_EMERGENCY`: the emergency stop; the plan asks for it as its feed-forward and control
  applies what the plan asks.
"""

from __future__ import annotations

A_COMF = 1.5  # [m/s^2] comfortable
A_FIRM = 3.0  # [m/s^2] firm
A_HARD = 5.0  # [m/s^2] hard
A_FLAT = 4.0  # [m/s^2] DECS's acceptance for a flat tyre (UN R157's bound on a minimum-risk
#   manoeuvre is the same)
A_EMERGENCY = 8.0  # [m/s^2] near the tyres' grip (mu g, mu ~ 1)
