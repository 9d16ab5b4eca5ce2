"""Which actions on the car the stack drives are its driver's inputs
(`ego_actions.driver_input`): a table of the mapping."""

from __future__ import annotations

import pytest

from avsim.scenario.openscenario.ego_actions import driver_input
from avsim.scenario.openscenario.model import (
    AbsoluteTargetLane,
    AbsoluteTargetLaneOffset,
    AbsoluteTargetSpeed,
    ActivateControllerAction,
    LaneChangeAction,
    LaneOffsetAction,
    LaneOffsetDynamics,
    OverrideControllerValueAction,
    PedalOverride,
    RelativeTargetSpeed,
    SpeedAction,
    TransitionDynamics,
)

DYN = TransitionDynamics("linear", "rate", 2.0, None)
PLAYED = [
    SpeedAction(DYN, AbsoluteTargetSpeed(10.0)),
    SpeedAction(DYN, RelativeTargetSpeed("Lead", 2.0, "delta", continuous=False)),
    LaneChangeAction(DYN, AbsoluteTargetLane("-2"), None),
    LaneChangeAction(DYN, AbsoluteTargetLane("-2"), 0.0),
    OverrideControllerValueAction((PedalOverride("brake", True, 0.5, None),)),
    ActivateControllerAction(True, True, None, None),
]
REFUSED = [
    (SpeedAction(DYN, RelativeTargetSpeed("Lead", 2.0, "delta", continuous=True)),
     "continuous relative target"),
    (LaneChangeAction(DYN, AbsoluteTargetLane("-2"), 0.5), "targetLaneOffset"),
    (LaneOffsetAction(False, LaneOffsetDynamics(None, "linear"),
                      AbsoluteTargetLaneOffset(0.5)), "LaneOffsetAction on the car"),
]


@pytest.mark.parametrize("action", PLAYED)
def test_a_driver_s_input_is_played(action: object) -> None:
    assert driver_input(action) is None


@pytest.mark.parametrize(("action", "says"), REFUSED)
def test_anything_else_is_refused_with_its_reason(action: object, says: str) -> None:
    problem = driver_input(action)
    assert problem is not None and says in problem
