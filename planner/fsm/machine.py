"""The one shape of every state machine in the planner: an enum of states, a transition table
as data, a pure transition function over it, and the live machine that applies a change.

A table is an ordered tuple of `Row`s: the states a row leaves (`sources`), the state it
enters (`target`), its guard, the guard's condition as written in the docs (`when`) and the
reason logged with the change. For the current state, the rows whose sources hold it are
tried in table order and the first whose guard holds is taken; none holding means stay.
So the order of rows is part of the table (a row listed first wins where conditions
overlap). `next_state` is the pure function; `Machine` keeps the state of one run and
turns a taken row into a `StateChange` for the log and the results.

`render(table)` writes a table for a module docstring; each machine's tests check that its
docstring shows exactly its table, and walk the table row by row.
"""

from __future__ import annotations

import enum
import math
import textwrap
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Generic, TypeVar

S = TypeVar("S", bound=enum.Enum)  # the machine's states
X = TypeVar("X")  # the input of one step
P = TypeVar("P")  # what the guards read besides the input (parameters, derived values)

Guard = Callable[[S, X, P], bool]  # (state now, input, context) -> the row holds
Reason = str | Callable[[X, P], str]  # the text logged, or how to write it from the input


@dataclass(frozen=True, slots=True)
class StateChange:
    """One change of a planner state machine, with its reason (for the log and results)."""

    t: float  # [s]
    machine: str  # e.g. "lane_source", "motion", "control", "acc"
    source: str  # the state left (its enum value)
    target: str  # the state entered (its enum value)
    reason: str


@dataclass(frozen=True, slots=True)
class Transition(Generic[S]):
    """A change of state a table allows: where to, and why."""

    to: S
    reason: str


@dataclass(frozen=True, slots=True)
class Row(Generic[S, X, P]):
    """One row of a transition table."""

    sources: frozenset[S]  # the states this row leaves
    target: S
    guard: Guard[S, X, P]
    when: str  # the guard's condition, as the docs' table shows it
    reason: Reason[X, P]  # logged with the change

    def reason_for(self, x: X, p: P) -> str:
        return self.reason if isinstance(self.reason, str) else self.reason(x, p)


@dataclass(frozen=True, slots=True)
class Table(Generic[S, X, P]):
    """An ordered transition table (module doc) over the states of `states`."""

    states: type[S]
    rows: tuple[Row[S, X, P], ...]
    _by_state: dict[S, tuple[Row[S, X, P], ...]] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        by_state = {s: tuple(r for r in self.rows if s in r.sources) for s in self.states}
        object.__setattr__(self, "_by_state", by_state)

    def rows_from(self, state: S) -> tuple[Row[S, X, P], ...]:
        """The rows that leave `state`, in the order they are tried."""
        return self._by_state[state]

    @property
    def edges(self) -> frozenset[tuple[S, S]]:
        """Every (from, to) pair the table allows."""
        return frozenset((s, r.target) for r in self.rows for s in r.sources)


def fired_row(table: Table[S, X, P], state: S, x: X, p: P) -> Row[S, X, P] | None:
    """The row of `table` taken from `state` for input `x`, or None (stay)."""
    return next((row for row in table.rows_from(state) if row.guard(state, x, p)), None)


def next_state(table: Table[S, X, P], state: S, x: X, p: P) -> Transition[S] | None:
    """The change `table` makes from `state` for input `x`, or None to stay."""
    row = fired_row(table, state, x, p)
    return None if row is None else Transition(row.target, row.reason_for(x, p))


class Machine(Generic[S]):
    """The live state of one machine in one run: its state and when it was entered."""

    def __init__(self, name: str, initial: S) -> None:
        self.name = name  # the machine's name in the log and the recording
        self.state = initial
        self.since = -math.inf  # [s] when the state was entered (-inf: from the start)

    def apply(self, t: float, change: Transition[S] | None) -> tuple[StateChange, ...]:
        """Take `change` (if any) at time `t` [s]; the log's record of it."""
        if change is None:
            return ()
        old, self.state, self.since = self.state, change.to, t
        return (StateChange(t, self.name, old.value, change.to.value, change.reason),)


def render(table: Table[S, X, P], names: Callable[[frozenset[S]], str] | None = None,
           width: int = 92) -> str:
    """The table for a module docstring: one numbered item per row, in table order,
    ``<from> -> <to>: <when>``, wrapped to `width` characters. `names` writes a row's source
    states (default: their values, comma separated)."""
    def sources(states: frozenset[S]) -> str:
        if names is not None:
            return names(states)
        return ", ".join(s.value for s in _ordered(table.states, states))

    items = []
    for k, row in enumerate(table.rows, 1):
        text = f"{k}. {sources(row.sources)} -> {row.target.value}: {row.when}"
        indent = " " * len(f"{k}. ")
        items.append(textwrap.fill(text, width, subsequent_indent=indent,
                                   break_on_hyphens=False))
    return "\n".join(items)


def _ordered(states: type[S], chosen: Iterable[S]) -> list[S]:
    chosen = set(chosen)
    return [s for s in states if s in chosen]
