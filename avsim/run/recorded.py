"""Where the run's states leave the stack for the reports: the stack's state changes and
per-tick states (its enums) as recorded data (`avsim.report.states`: plain values, as the
result JSON has them), so the reports read them without importing stack code."""

from __future__ import annotations

import enum
from collections.abc import Iterable

from avsim.report.states import RecordedChange
from planner.fsm.machine import StateChange


def recorded_changes(changes: Iterable[StateChange]) -> tuple[RecordedChange, ...]:
    """The stack's state changes, each as recorded (time [s], machine, from, to, reason)."""
    return tuple(RecordedChange(c.t, c.machine, c.source, c.target, c.reason)
                 for c in changes)


def recorded_states(states: Iterable[enum.Enum]) -> list[str]:
    """A per-tick series of a machine's states, by their recorded values."""
    return [str(s.value) for s in states]
