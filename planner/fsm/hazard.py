"""The hazard lights: off until a flat tyre is detected, then on for good (the car pulls
over and stops; DECS's minimum-risk manoeuvre). The smallest machine, in the same shape as
the others (`planner.fsm.machine`):

1. off -> on: a flat tyre is detected
"""

from __future__ import annotations

import enum

from planner.fsm.machine import Row, Table, Transition, next_state, render


class HazardLights(enum.Enum):
    OFF = "off"
    ON = "on"


def _flat(_s: HazardLights, flat: bool, _p: None) -> bool:
    return flat


TABLE: Table[HazardLights, bool, None] = Table(HazardLights, (
    Row(frozenset({HazardLights.OFF}), HazardLights.ON, _flat, "a flat tyre is detected",
        "flat tyre"),
))


def transition(state: HazardLights, flat: bool) -> Transition[HazardLights] | None:
    """The change for `flat` (a flat tyre detected now), or None to stay (`TABLE`)."""
    return next_state(TABLE, state, flat, None)


if __name__ == "__main__":  # print the table for the module doc
    print(render(TABLE))
