"""The storyboard element machine: every row of its table walked, and the doc shows it."""

from __future__ import annotations

import pytest

from avsim.run.storyboard import elements
from avsim.run.storyboard.elements import (
    TABLE,
    ElementState,
    TransitionKind,
    TransitionRequest,
    transition,
)
from tests.planner.fsm.tables import doc_shows_table, unwalked_rows

S, K = ElementState, TransitionKind
R = TransitionRequest

CASES = [
    (S.STANDBY, R(K.START), S.RUNNING),
    (S.STANDBY, R(K.START, last_execution=False), S.RUNNING),
    (S.STANDBY, R(K.SKIP), S.STANDBY),
    (S.STANDBY, R(K.STOP), S.COMPLETE),
    (S.STANDBY, R(K.END), None),
    (S.RUNNING, R(K.END), S.COMPLETE),
    (S.RUNNING, R(K.END, last_execution=False), S.STANDBY),
    (S.RUNNING, R(K.STOP), S.COMPLETE),
    (S.RUNNING, R(K.START), None),
    (S.RUNNING, R(K.SKIP), None),
    (S.COMPLETE, R(K.START), None),
    (S.COMPLETE, R(K.END), None),
    (S.COMPLETE, R(K.STOP), None),
    (S.COMPLETE, R(K.SKIP), None),
]


def test_every_row_is_walked() -> None:
    assert unwalked_rows(TABLE, CASES, lambda _x: None) == []


def test_doc_shows_the_table() -> None:
    assert doc_shows_table(elements, TABLE)


@pytest.mark.parametrize(("state", "request_", "expected"), CASES)
def test_transition_names_the_transition(state: ElementState, request_: TransitionRequest,
                                         expected: ElementState | None) -> None:
    got = transition(state, request_)
    if expected is None:
        assert got is None
    else:
        assert got == (expected, request_.kind)
