"""The stack's states as a run records them, the reports' own view of them: a state change
as the result JSON has it (``state_changes``: ``t``, ``machine``, ``from``, ``to``,
``reason``, every one a plain value) and the recorded names of the motion FSM's states the
reports tell apart. The reports import no stack code; the runner turns the stack's changes
and states into these where it hands a run to them (`avsim.run.recorded`).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class RecordedChange:
    """One recorded change of a state machine of the stack."""

    t: float  # [s] sim time of the change
    machine: str  # the machine, as recorded: "acc", "motion", "lane_source", "control", ...
    source: str  # the state left (the result JSON's ``from``)
    target: str  # the state entered (``to``)
    reason: str  # why, as logged


MOTION_MACHINE = "motion"  # the motion FSM's name in the recorded changes
# the motion FSM's states, by their recorded values
LANE_KEEP = "lane_keep"
LANE_CHANGE_LEFT = "lane_change_left"
LANE_CHANGE_RIGHT = "lane_change_right"
TURN_RIGHT = "turn_right"
TURN_LEFT = "turn_left"
U_TURN = "u_turn"
MOTION_STATES = (LANE_KEEP, LANE_CHANGE_LEFT, LANE_CHANGE_RIGHT, TURN_RIGHT, TURN_LEFT,
                 U_TURN)
LANE_CHANGES = frozenset({LANE_CHANGE_LEFT, LANE_CHANGE_RIGHT})  # the lane-changing states
