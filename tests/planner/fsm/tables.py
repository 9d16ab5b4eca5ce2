"""Checks every machine's table test runs (`planner.fsm.machine`): the cases walk every row
of the table's data, and the module doc shows the table as the data has it."""

from __future__ import annotations

import enum
from collections.abc import Callable, Sequence
from types import ModuleType
from typing import Any

from planner.fsm.machine import Table, fired_row, render

Case = tuple[enum.Enum, Any, enum.Enum | None]  # (from, input, expected next state or None)


def unwalked_rows(table: Table[Any, Any, Any], cases: Sequence[Case],
                  context: Callable[[Any], Any]) -> list[str]:
    """The rows of `table` no case fires (`context(input)` gives the guards' context), and
    each case whose fired row disagrees with its expectation, as messages."""
    problems, walked = [], set()
    for state, inp, expected in cases:
        row = fired_row(table, state, inp, context(inp))
        got = None if row is None else row.target
        if got is not expected:
            problems.append(f"from {state.value}: {got} expected {expected} ({inp})")
        if row is not None:
            walked.add(id(row))
    problems += [f"row {k}: {row.when} is walked by no case"
                 for k, row in enumerate(table.rows, 1) if id(row) not in walked]
    return problems


def doc_shows_table(module: ModuleType, table: Table[Any, Any, Any],
                    names: Callable[[frozenset[Any]], str] | None = None) -> bool:
    """Whether `module`'s docstring holds `table` as `render` writes it."""
    return module.__doc__ is not None and render(table, names=names) in module.__doc__
