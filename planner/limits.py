"""The decelerations and jerks the planner plans with, in one place [m/s^2, m/s^3, positive
numbers].

Every parameter set of the planner that brakes takes its default from here, so that the
comfort and emergency limits are stated once:

- `A_COMF`: comfortable braking: approaches to lower limits, curves, stop lines,
  crossings and bumps, the ACC's d_max and trail law, the lane-lost ramp;
- `A_FIRM`: firm braking: the yellow-light rule's and the junction commitment's "can still
  stop";
- `A_COMF_MAX`, `J_COMF`: the most deceleration a comfortable law plans and the jerk at
  which the speed loop lets it build (ISO 15622 / ISO 22179: an ACC decelerates at most
  `A_ISO` averaged over 2 s, and its deceleration rises at most at `J_ISO` averaged over
  1 s; the planned figures stay below them, with room for the speed loop's ripple). A law
  plans more only when no comfortable stop is left (`planner.acc_control`);
- `A_ISO_PLAN`, `A_ISO_MAX`, `J_ISO_PLAN`: where no comfortable stop is left but one within
  ISO's own limits is (a stopped car revealed a little late), what the ACC plans (the
  least deceleration that still stops, at least `A_ISO_PLAN`, at most `A_ISO_MAX`) and the
  jerk at which the speed loop builds it: still under `A_ISO` and `J_ISO`;
- `A_HARD`: hard braking: the most the ACC plans when no stop within ISO's limits is left;
  beyond it the control FSM calls an emergency;
- `A_FLAT`: the most a flat tyre's stop may plan (the DECS acceptance);
- `A_EMERGENCY`: the emergency stop; the plan asks for it as its feed-forward and control
  applies what the plan asks.

And the one distance every braking plan ahead must fit in: `SIGHT`, the bumper gap [m] at
which the forward LiDAR's track of a car is confirmed (`PlannerParams.sight_range`, the
speed cap; `PassParams.sight`, a pass through the oncoming lane).
"""

from __future__ import annotations

A_COMF = 1.5  # [m/s^2] comfortable
A_FIRM = 3.0  # [m/s^2] firm
A_ISO = 3.5  # [m/s^2] ISO 15622 / 22179 (above 20 m/s): an ACC's deceleration, 2 s average
J_ISO = 2.5  # [m/s^3] ISO 15622 / 22179 (above 20 m/s): the rise of its deceleration, 1 s
#   average
A_COMF_MAX = 3.0  # [m/s^2] the most a comfortable law plans (under A_ISO)
J_COMF = 2.0  # [m/s^3] the rise of a comfortable plan's deceleration (under J_ISO)
A_ISO_PLAN = 3.3  # [m/s^2] a plan within ISO's limits asks at least this ...
A_ISO_MAX = 3.45  # [m/s^2] ... and at most this, as `need` asks (under A_ISO)
J_ISO_PLAN = 2.4  # [m/s^3] the rise of such a plan's deceleration (under J_ISO)
A_HARD = 5.0  # [m/s^2] hard
A_FLAT = 4.0  # [m/s^2] DECS's acceptance for a flat tyre (UN R157's bound on a minimum-risk
#   manoeuvre is the same)
A_EMERGENCY = 8.0  # [m/s^2] near the tyres' grip (mu g, mu ~ 1)
SIGHT = 55.0  # [m] the forward sensing's confirmed sight of a car (module doc)
