"""How long the stack held each mode of a state machine: the shortest hold is the measure
of mode chatter (outside safety transitions, no ACC mode is to be held for less than
0.5 s). A hold is the time between entering a mode and leaving it; the mode held at the
end of the run is not counted (it was not left), nor are safety transitions: a hold of a
safety mode (entered because braking could not wait, `SAFETY_MODES`: it lasts as long as
the danger does) or one ended by entering it. `holds` lists the holds this rule counts,
`shortest_hold` is their least (the run's metric ``acc_shortest_mode``, the chatter test's
measure, and `avsim.report.mode_holds` over many runs)."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

SAFETY_MODES = frozenset({"brake", "pedestrian", "flat"})  # ACC modes entered for safety


class Change(Protocol):
    """A state change as the rule reads it: the stack's (`planner.fsm.machine.StateChange`)
    or a recorded one (`avsim.report.states.RecordedChange`)."""

    @property
    def t(self) -> float: ...  # [s]
    @property
    def machine(self) -> str: ...
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
    """The holds of the modes of `machine` not in `safety` that ended by a change into a
    mode not in `safety`, in time order (module doc)."""
    mine = [c for c in changes if c.machine == machine]
    return [Hold(a.target, a.t, b.t - a.t, b.target) for a, b in itertools.pairwise(mine)
            if a.target not in safety and b.target not in safety]


def shortest_hold(changes: Sequence[Change], machine: str,
                  safety: frozenset[str] = SAFETY_MODES) -> float:
    """[s] the shortest time a mode of `machine` not in `safety` was held before a change
    into a mode not in `safety`; inf if there is none (no such change)."""
    return min((h.duration for h in holds(changes, machine, safety)), default=math.inf)
