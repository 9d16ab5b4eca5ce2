"""The hazard lights: on for good once a flat tyre is detected (the car pulls over and stops;
DECS's minimum-risk manoeuvre), and on during a minimum-risk stop in lane after a sensor
fault (the lane lost, `planner.fsm.lane_source`; the LiDAR lost, `planner.fsm.sensing`),
off again when that stop is over and the car resumes. The smallest machine, in the same
shape as the others (`planner.fsm.machine`):

1. off -> on: a flat tyre is detected
2. off -> on: a minimum-risk stop in lane after a sensor fault
3. on -> off: no flat tyre, no minimum-risk stop: the car resumes
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from planner.fsm.machine import Row, Table, Transition, next_state, render


class HazardLights(enum.Enum):
    OFF = "off"
    ON = "on"


@dataclass(frozen=True, slots=True)
class HazardInput:
    flat: bool = False  # a flat tyre is detected (it stays detected)
    stop: str | None = None  # why a minimum-risk stop in lane is under way; None: none


def _flat(_s: HazardLights, x: HazardInput, _p: None) -> bool:
    return x.flat


def _stop(_s: HazardLights, x: HazardInput, _p: None) -> bool:
    return x.stop is not None


def _clear(_s: HazardLights, x: HazardInput, _p: None) -> bool:
    return not x.flat and x.stop is None


TABLE: Table[HazardLights, HazardInput, None] = Table(HazardLights, (
    Row(frozenset({HazardLights.OFF}), HazardLights.ON, _flat, "a flat tyre is detected",
        "flat tyre"),
    Row(frozenset({HazardLights.OFF}), HazardLights.ON, _stop,
        "a minimum-risk stop in lane after a sensor fault",
        lambda x, p: f"minimum-risk stop: {x.stop}"),
    Row(frozenset({HazardLights.ON}), HazardLights.OFF, _clear,
        "no flat tyre, no minimum-risk stop: the car resumes", "minimum-risk stop over"),
))


def transition(state: HazardLights, x: HazardInput) -> Transition[HazardLights] | None:
    """The change for `x`, or None to stay (`TABLE`)."""
    return next_state(TABLE, state, x, None)


if __name__ == "__main__":  # print the table for the module doc
    print(render(TABLE))
