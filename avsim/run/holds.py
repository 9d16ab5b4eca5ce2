"""How long the stack held each mode of a state machine: the shortest hold is the measure
of mode chatter (issue K: outside safety transitions, no ACC mode is held for less than
0.5 s). A hold is the time between entering a mode and leaving it; the mode held at the
end of the run is not counted (it was not left), nor are safety transitions: a hold of a
safety mode (entered because braking could not wait, `SAFETY_MODES`: it lasts as long as
the danger does) or one ended by entering it."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

from planner.fsm.machine import StateChange

SAFETY_MODES = frozenset({"brake", "pedestrian", "flat"})  # ACC modes entered for safety


def shortest_hold(changes: Sequence[StateChange], machine: str,
                  safety: frozenset[str] = SAFETY_MODES) -> float:
    """[s] the shortest time a mode of `machine` not in `safety` was held before a change
    into a mode not in `safety`; inf if there is none (no such change)."""
    mine = [c for c in changes if c.machine == machine]
    holds = [b.t - a.t for a, b in itertools.pairwise(mine)
             if a.target not in safety and b.target not in safety]
    return min(holds, default=math.inf)
