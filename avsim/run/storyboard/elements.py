"""The state machine of one storyboard element (OpenSCENARIO 1.x: story, act, maneuver group,
maneuver, event, action): three states, four transitions, as a table of data
(`planner.fsm.machine`). The input is the transition the runtime asks for
(`TransitionRequest`); the row taken names the transition as its reason. Transitions
(`TABLE`), tried in this order from the state the element is in:

1. standbyState -> runningState: startTransition asked (its start trigger fired, or its
   parent started it)
2. standbyState -> standbyState: skipTransition asked (an event of priority skip whose
   trigger fired while another event of its maneuver runs)
3. runningState -> completeState: endTransition asked, its last execution (all its children
   completed, or the world reported the action done)
4. runningState -> standbyState: endTransition asked, executions left
   (maximumExecutionCount: re-armed)
5. standbyState, runningState -> completeState: stopTransition asked (a stop trigger, or an
   event overwritten by another)

A request no row allows (e.g. a start of a complete element) is ignored (None: stay). As
esmini (`StoryBoardElement::End`), an end with executions left goes back to standby; the
1.2 spec draws the same loop for events and maneuver groups.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from planner.fsm.machine import Row, Table, Transition, next_state, render


class ElementState(enum.Enum):
    STANDBY = "standbyState"
    RUNNING = "runningState"
    COMPLETE = "completeState"


class TransitionKind(enum.Enum):
    START = "startTransition"
    END = "endTransition"
    STOP = "stopTransition"
    SKIP = "skipTransition"


@dataclass(frozen=True, slots=True)
class TransitionRequest:
    """The transition asked of an element, and whether this execution is its last."""

    kind: TransitionKind
    last_execution: bool = True  # executions so far >= maximumExecutionCount


@dataclass(frozen=True, slots=True)
class TransitionRecord:
    """One transition that happened, for `StoryRuntime.history` and the state conditions."""

    t: float  # [s]
    element_type: str  # story, act, maneuverGroup, maneuver, event, action
    name: str
    transition: TransitionKind
    state: ElementState  # the state entered




def _end_last(_s: ElementState, x: TransitionRequest, _p: None) -> bool:
    return x.kind is TransitionKind.END and x.last_execution


def _end_again(_s: ElementState, x: TransitionRequest, _p: None) -> bool:
    return x.kind is TransitionKind.END and not x.last_execution


def _start(_s: ElementState, x: TransitionRequest, _p: None) -> bool:
    return x.kind is TransitionKind.START


def _skip(_s: ElementState, x: TransitionRequest, _p: None) -> bool:
    return x.kind is TransitionKind.SKIP


def _stop(_s: ElementState, x: TransitionRequest, _p: None) -> bool:
    return x.kind is TransitionKind.STOP


E = ElementState
K = TransitionKind

TABLE: Table[ElementState, TransitionRequest, None] = Table(ElementState, (
    Row(frozenset({E.STANDBY}), E.RUNNING, _start,
        "startTransition asked (its start trigger fired, or its parent started it)",
        K.START.value),
    Row(frozenset({E.STANDBY}), E.STANDBY, _skip,
        "skipTransition asked (an event of priority skip whose trigger fired while another "
        "event of its maneuver runs)", K.SKIP.value),
    Row(frozenset({E.RUNNING}), E.COMPLETE, _end_last,
        "endTransition asked, its last execution (all its children completed, or the world "
        "reported the action done)", K.END.value),
    Row(frozenset({E.RUNNING}), E.STANDBY, _end_again,
        "endTransition asked, executions left (maximumExecutionCount: re-armed)", K.END.value),
    Row(frozenset({E.STANDBY, E.RUNNING}), E.COMPLETE, _stop,
        "stopTransition asked (a stop trigger, or an event overwritten by another)",
        K.STOP.value),
))


def transition(state: ElementState,
               request: TransitionRequest) -> tuple[ElementState, TransitionKind] | None:
    """The state entered and the transition taken for `request` from `state`, or None when
    the table allows none (the request is ignored)."""
    change: Transition[ElementState] | None = next_state(TABLE, state, request, None)
    return None if change is None else (change.to, TransitionKind(change.reason))


if __name__ == "__main__":  # print the table for the module doc
    print(render(TABLE))
