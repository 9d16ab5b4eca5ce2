"""The shortest hold of a machine's modes (`avsim.run.holds`), the measure of chatter."""

from __future__ import annotations

import math

import pytest

from avsim.report.states import RecordedChange
from avsim.run.holds import holds, shortest_hold
from avsim.run.recorded import recorded_changes
from planner.fsm.machine import StateChange


def change(t: float, source: str, target: str, machine: str = "acc") -> StateChange:
    return StateChange(t, machine, source, target, "")


@pytest.mark.parametrize(("changes", "expected"), [
    ([], math.inf),
    ([change(0.0, "acc_off", "cruise")], math.inf),  # held to the end: not counted
    ([change(0.0, "acc_off", "cruise"), change(5.0, "cruise", "trail"),
      change(5.1, "trail", "cruise"), change(9.0, "cruise", "trail")], pytest.approx(0.1)),
    # a hold ended by braking (d <= d_min) is a safety transition
    ([change(0.0, "acc_off", "cruise"), change(5.0, "cruise", "trail"),
      change(5.1, "trail", "brake"), change(7.0, "brake", "trail"),
      change(9.5, "trail", "cruise")], pytest.approx(2.5)),
    # ... and so is a short hold of the braking mode itself
    ([change(0.0, "acc_off", "cruise"), change(5.0, "cruise", "brake"),
      change(5.1, "brake", "trail"), change(8.0, "trail", "cruise")], pytest.approx(2.9)),
    # the mode switched on in is held until the first choice (a lead confirmed): not counted
    ([change(0.0, "acc_off", "cruise"), change(0.3, "cruise", "trail"),
      change(80.0, "trail", "cruise")], pytest.approx(79.7)),
    # ... also when the machine is switched on again later (a driver's override ends); the
    # off state is no mode
    ([change(0.0, "acc_off", "cruise"), change(4.0, "cruise", "trail"),
      change(9.0, "trail", "acc_off"), change(12.0, "acc_off", "trail"),
      change(12.2, "trail", "cruise"), change(20.0, "cruise", "trail")],
     pytest.approx(5.0)),
    # other machines' changes are not this machine's holds
    ([change(0.0, "acc_off", "cruise"), change(1.0, "cruise", "trail"),
      change(1.2, "keep", "change", "motion"), change(1.3, "change", "keep", "motion"),
      change(4.0, "trail", "cruise")], pytest.approx(3.0)),
])
def test_shortest_hold(changes: list[StateChange], expected: object) -> None:
    assert shortest_hold(changes, "acc") == expected


def test_holds_lists_what_shortest_hold_counts() -> None:
    changes = [change(0.0, "acc_off", "cruise"), change(5.0, "cruise", "brake"),
               change(5.1, "brake", "trail"), change(8.0, "trail", "cruise"),
               change(8.2, "cruise", "yield"), change(9.0, "yield", "cruise")]
    got = holds(changes, "acc")
    assert [(h.mode, h.then) for h in got] == [("trail", "cruise"), ("cruise", "yield"),
                                               ("yield", "cruise")]
    assert got[1].t == 8.0 and got[1].duration == pytest.approx(0.2)
    assert shortest_hold(changes, "acc") == min(h.duration for h in got)


def test_recorded_changes_give_the_same_holds() -> None:
    """The reports read the holds from recorded changes (`avsim.report.states`), the run's
    metric from the stack's: the same rule gives the same holds."""
    changes = [change(0.0, "acc_off", "cruise"), change(5.0, "cruise", "trail"),
               change(5.1, "trail", "cruise"), change(6.0, "keep", "change", "motion"),
               change(9.0, "cruise", "brake"), change(9.4, "brake", "cruise"),
               change(12.0, "cruise", "trail")]
    recorded = recorded_changes(changes)
    assert all(type(c) is RecordedChange for c in recorded)
    assert holds(recorded, "acc") == holds(changes, "acc")
    assert shortest_hold(recorded, "acc") == pytest.approx(0.1)
