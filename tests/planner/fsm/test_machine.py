"""The generic machine (`planner.fsm.machine`): rows are tried in table order for the state
the machine is in, a change is logged once with its reason, and the docs render the data."""

from __future__ import annotations

import enum
import math

from planner.fsm.machine import Machine, Row, Table, Transition, fired_row, next_state, render


class Light(enum.Enum):
    RED = "red"
    GREEN = "green"
    BLINK = "blink"


def _over(limit: float):  # type: ignore[no-untyped-def]
    def holds(_s: Light, x: float, _p: None) -> bool:
        return x > limit
    return holds


ROWS = (
    Row(frozenset({Light.RED}), Light.BLINK, _over(10.0), "x > 10", "far over"),
    Row(frozenset({Light.RED, Light.BLINK}), Light.GREEN, _over(1.0), "x > 1",
        lambda x, _p: f"x is {x:.1f}"),
)
TABLE: Table[Light, float, None] = Table(Light, ROWS)


def test_rows_are_tried_in_table_order_for_the_state_now() -> None:
    assert fired_row(TABLE, Light.RED, 20.0, None) is ROWS[0]  # both hold: the first wins
    assert fired_row(TABLE, Light.BLINK, 20.0, None) is ROWS[1]  # row 0 does not leave it
    assert fired_row(TABLE, Light.GREEN, 20.0, None) is None  # no row leaves green
    assert next_state(TABLE, Light.RED, 0.5, None) is None
    assert next_state(TABLE, Light.RED, 2.0, None) == Transition(Light.GREEN, "x is 2.0")
    assert TABLE.edges == {(Light.RED, Light.BLINK), (Light.RED, Light.GREEN),
                           (Light.BLINK, Light.GREEN)}


def test_the_machine_logs_each_change_with_its_time_and_reason() -> None:
    m = Machine("light", Light.RED)
    assert m.since == -math.inf
    assert m.apply(1.0, None) == () and m.state is Light.RED
    (change,) = m.apply(2.5, next_state(TABLE, m.state, 2.0, None))
    assert (change.t, change.machine, change.source, change.target, change.reason) == (
        2.5, "light", "red", "green", "x is 2.0")
    assert m.state is Light.GREEN and m.since == 2.5


def test_render_writes_one_numbered_wrapped_item_per_row() -> None:
    text = render(TABLE, width=30)
    assert text.splitlines()[0] == "1. red -> blink: x > 10"
    assert text.splitlines()[1] == "2. red, blink -> green: x > 1"
    assert all(len(line) <= 30 for line in render(TABLE, width=30).splitlines())
