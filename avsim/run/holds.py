"""How long the stack held each mode of a state machine: the shortest hold is the measure
of mode chatter (outside safety transitions, no ACC mode is to be held for less than
0.5 s). A hold is the time between entering a mode and leaving it. Not counted:
- the mode held at the end of the run (it was not left);
- safety transitions: a hold of a safety mode (entered because braking could not wait,
  `SAFETY_MODES`: it lasts as long as the danger does) or one ended by entering it;
- the machine's off state (`OFF_STATES`: no mode, the driver has the car), and the hold of
  the mode it is switched on in (entered from its off state): the stack has chosen no mode
  yet, and that hold lasts until its first choice, as long as confirming what is ahead
  takes (a vehicle ahead at switch-on becomes the lead once confirmed).
`holds` lists the holds this rule counts, `shortest_hold` is their least (the run's metric
``acc_shortest_mode``, the chatter test's measure, and `avsim.report.mode_holds` over many
runs)."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

SAFETY_MODES = frozenset({"brake", "pedestrian", "flat"})  # ACC modes entered for safety
OFF_STATES = frozenset({"acc_off"})  # a machine's state while switched off


class Change(Protocol):
    """A state change as the rule reads it: the stack's (`planner.fsm.machine.StateChange`)
    or a recorded one (`avsim.report.states.RecordedChange`)."""

    @property
    def t(self) -> float: ...  # [s]
    @property
    def machine(self) -> str: ...
    @property
    def source(self) -> str: ...  # the state left
    @property
    def target(self) -> str: ...  # the state entered


@dataclass(frozen=True, slots=True)
class Hold:
    """One counted hold of a mode."""

    mode: str  # the mode held
    t: float  # [s] when it was entered
    duration: float  # [s] how long it was held
    then: str  # the mode it was left for


def holds(changes: Sequence[Change], machine: str,
          safety: frozenset[str] = SAFETY_MODES) -> list[Hold]:
    """The holds of the modes of `machine` not in `safety` nor off, entered other than by
    switching the machine on, that ended by a change into a mode not in `safety`, in time order
    (module doc)."""
    mine = [c for c in changes if c.machine == machine]
    return [Hold(a.target, a.t, b.t - a.t, b.target) for a, b in itertools.pairwise(mine)
            if a.target not in safety and b.target not in safety
            and a.source not in OFF_STATES and a.target not in OFF_STATES]


def shortest_hold(changes: Sequence[Change], machine: str,
                  safety: frozenset[str] = SAFETY_MODES) -> float:
    """[s] the shortest hold `holds` counts; inf if there is none (no such change)."""
    return min((h.duration for h in holds(changes, machine, safety)), default=math.inf)
