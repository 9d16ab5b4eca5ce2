"""The all-way-stop order (`world.actors.all_way_stop`): first to stop, first to go; ties
to the right; a turn once given stays until its vehicle leaves, or passes on when it is not
taken."""

from __future__ import annotations

import math

import pytest

from world.actors.all_way_stop import GRANT_TIMEOUT, TIE, AllWayStop, first_in_order, on_right

EAST, NORTH, WEST, SOUTH = 0.0, 0.5 * math.pi, math.pi, -0.5 * math.pi
J = (1, 1)


@pytest.mark.parametrize(("heading", "other", "right"), [
    (EAST, NORTH, True),  # heading east, the car from the south arm travels north
    (EAST, SOUTH, False),  # from the north arm: on the left
    (EAST, WEST, False),  # oncoming
    (NORTH, WEST, True),
    (WEST, SOUTH, True),
    (SOUTH, EAST, True),
    (SOUTH, -0.5 * math.pi + 2.0 * math.pi + 0.5 * math.pi, True),  # angles wrap
])
def test_on_right(heading: float, other: float, right: bool) -> None:
    assert on_right(heading, other) is right


# (arrivals: key -> ([s], heading), whose turn)
ORDER_TABLE = [
    ({}, None),
    ({"a": (0.0, EAST)}, "a"),
    ({"a": (0.0, EAST), "b": (2.0, NORTH)}, "a"),  # first to stop
    ({"a": (2.0, EAST), "b": (0.0, SOUTH)}, "b"),
    ({"a": (0.0, EAST), "b": (0.5, NORTH)}, "b"),  # a tie: b comes from a's right
    ({"a": (0.5, EAST), "b": (0.0, SOUTH)}, "a"),  # a tie: a comes from b's right
    ({"a": (0.0, EAST), "b": (0.3, WEST)}, "a"),  # opposite: neither on the other's right
    ({"a": (0.0, EAST), "b": (0.2, NORTH), "c": (0.4, WEST)}, "c"),  # c is right of b,
    #   b right of a, nobody right of c
    ({"a": (0.0, EAST), "b": (0.1, NORTH), "c": (0.2, WEST), "d": (0.3, SOUTH)}, "a"),
    #   four at once: everybody has one on the right, the earliest goes
    ({"a": (0.0, EAST), "b": (0.9, NORTH), "c": (5.0, WEST)}, "b"),  # c is no tie
]


@pytest.mark.parametrize(("waiting", "first"), ORDER_TABLE)
def test_first_in_order(waiting: dict[str, tuple[float, float]], first: str | None) -> None:
    assert first_in_order(waiting) == first


def test_nobody_goes_until_a_tie_is_possible_then_the_first() -> None:
    order = AllWayStop()
    order.arrive(J, "a", EAST, 10.0)
    assert order.turn(J, 10.0 + 0.5 * TIE) is None  # a tie could still come
    order.arrive(J, "b", NORTH, 10.0 + 0.6 * TIE)  # from a's right, within the tie
    assert order.turn(J, 10.0 + 1.1 * TIE) == "b"
    assert order.may_go(J, "b", 11.5) and not order.may_go(J, "a", 11.5)


def test_a_turn_stays_with_its_vehicle_until_it_leaves() -> None:
    order = AllWayStop()
    order.arrive(J, "a", EAST, 0.0)
    assert order.turn(J, 2.0) == "a"
    order.arrive(J, "b", NORTH, 1.9)  # later, though on a's right: a keeps its turn
    assert order.turn(J, 3.0) == "a"
    order.leave(J, "a")
    assert order.turn(J, 3.1) == "b"
    order.leave(J, "b")
    assert order.turn(J, 3.2) is None


def test_a_vehicle_arriving_twice_keeps_its_first_arrival() -> None:
    order = AllWayStop()
    order.arrive(J, "a", EAST, 1.0)
    order.arrive(J, "a", EAST, 4.0)
    assert order.arrived_at(J, "a") == 1.0
    assert order.arrived_at(J, "b") is None
    assert order.arrived_at((0, 0), "a") is None


def test_a_turn_not_taken_passes_to_the_next_vehicle() -> None:
    order = AllWayStop()
    order.arrive(J, "a", EAST, 0.0)
    order.arrive(J, "b", WEST, 3.0)
    assert order.turn(J, 2.0) == "a"
    assert order.turn(J, 2.0 + GRANT_TIMEOUT - 0.1) == "a"
    t = 2.0 + GRANT_TIMEOUT + 0.1
    assert order.turn(J, t) == "b"  # a stood on: b goes, a to the back of the order
    order.leave(J, "b")
    assert order.turn(J, t + TIE + 0.1) == "a"


def test_without_a_timeout_the_turn_never_passes_on() -> None:
    order = AllWayStop(grant_timeout=math.inf)
    order.arrive(J, "a", EAST, 0.0)
    order.arrive(J, "b", WEST, 3.0)
    assert order.turn(J, 1000.0) == "a"


def test_junctions_are_independent() -> None:
    order = AllWayStop()
    order.arrive(J, "a", EAST, 0.0)
    order.arrive((2, 1), "b", EAST, 5.0)
    assert order.turn(J, 7.0) == "a"
    assert order.turn((2, 1), 7.0) == "b"
    order.leave((3, 3), "a")  # a junction nobody waits at: nothing happens
