"""The motion FSM: every transition of its table as a row, with rows that must not fire."""

from __future__ import annotations

from dataclasses import replace

import pytest

from planner.fsm import motion
from planner.fsm.machine import fired_row
from planner.fsm.motion import (
    TABLE,
    Motion,
    MotionInput,
    MotionParams,
    Turn,
    is_pass,
    transition,
)
from tests.planner.fsm.tables import doc_shows_table, unwalked_rows

P = MotionParams()
M = Motion
T = 10.0  # [s] now; the last change was long ago unless a row says otherwise


def x(**kw: object) -> MotionInput:
    """Defaults: overtaking allowed, nothing blocked, no lane free, no route need."""
    return replace(MotionInput(t=T, since=0.0, overtake=True), **kw)  # type: ignore[arg-type]


# (name, from, input, expected next state or None to stay, abort)
TABLE_CASES = [
    # LANE_KEEP -> pull over (a flat tyre), before anything else
    ("keep_pull_over", M.LANE_KEEP, x(pull_over=True, right_free=True), M.LANE_CHANGE_RIGHT,
     False),
    ("keep_pull_over_first", M.LANE_KEEP,
     x(pull_over=True, right_free=True, turn=Turn.LEFT, blocked=True, left_free=True),
     M.LANE_CHANGE_RIGHT, False),
    ("keep_pull_over_waits_for_the_gap", M.LANE_KEEP,
     x(pull_over=True, blocked=True, left_free=True, turn=Turn.LEFT), None, False),
    # LANE_KEEP -> turns (the route's command at the junction)
    ("keep_turn_right", M.LANE_KEEP, x(turn=Turn.RIGHT), M.TURN_RIGHT, False),
    ("keep_turn_left", M.LANE_KEEP, x(turn=Turn.LEFT), M.TURN_LEFT, False),
    ("keep_u_turn", M.LANE_KEEP, x(turn=Turn.U_TURN), M.U_TURN, False),
    ("keep_turn_before_overtake", M.LANE_KEEP, x(turn=Turn.LEFT, blocked=True, left_free=True),
     M.TURN_LEFT, False),
    # LANE_KEEP -> route lane changes
    ("keep_route_right", M.LANE_KEEP, x(route_lane=-1, right_free=True), M.LANE_CHANGE_RIGHT,
     False),
    ("keep_route_left", M.LANE_KEEP, x(route_lane=1, left_free=True), M.LANE_CHANGE_LEFT, False),
    ("keep_route_waits_for_gap", M.LANE_KEEP, x(route_lane=-1, left_free=True), None, False),
    ("keep_route_no_overtake_away", M.LANE_KEEP,
     x(route_lane=-1, blocked=True, left_free=True), None, False),
    ("keep_route_needs_no_overtake_setting", M.LANE_KEEP,
     x(overtake=False, route_lane=-1, right_free=True), M.LANE_CHANGE_RIGHT, False),
    ("keep_route_waits_route_keep_time", M.LANE_KEEP,
     x(since=T - 0.5, route_lane=-1, right_free=True), None, False),
    # LANE_KEEP -> the driver's turn-signal stalk
    ("keep_driver_right", M.LANE_KEEP, x(overtake=False, driver_lane=-1, right_free=True),
     M.LANE_CHANGE_RIGHT, False),
    ("keep_driver_left", M.LANE_KEEP, x(overtake=False, driver_lane=1, left_free=True),
     M.LANE_CHANGE_LEFT, False),
    ("keep_driver_waits_for_gap", M.LANE_KEEP, x(driver_lane=1, right_free=True), None,
     False),
    ("keep_driver_waits_route_keep_time", M.LANE_KEEP,
     x(since=T - 0.5, driver_lane=1, left_free=True), None, False),
    ("keep_route_before_driver", M.LANE_KEEP,
     x(route_lane=-1, driver_lane=1, left_free=True, right_free=True), M.LANE_CHANGE_RIGHT,
     False),
    ("keep_driver_not_overtaken_away", M.LANE_KEEP,
     x(driver_lane=1, blocked=True, right_free=True), None, False),
    ("keep_driver_not_kept_right_away", M.LANE_KEEP,
     x(driver_lane=1, right_free=True, right_clear=True), None, False),
    # LANE_KEEP -> overtaking lane changes
    ("keep_overtake_left", M.LANE_KEEP, x(blocked=True, left_free=True), M.LANE_CHANGE_LEFT,
     False),
    ("keep_overtake_left_first", M.LANE_KEEP, x(blocked=True, left_free=True, right_free=True),
     M.LANE_CHANGE_LEFT, False),
    ("keep_overtake_right", M.LANE_KEEP, x(blocked=True, right_free=True), M.LANE_CHANGE_RIGHT,
     False),
    ("keep_blocked_nothing_free", M.LANE_KEEP, x(blocked=True), None, False),
    # a pass starts only if its path clears the vehicle ahead (e.g. from too near behind a
    # stopped car: the car waits in its lane); the other side may still do
    ("keep_overtake_left_waits_until_it_clears", M.LANE_KEEP,
     x(blocked=True, left_free=True, clears_left=False), None, False),
    ("keep_overtake_right_when_only_it_clears", M.LANE_KEEP,
     x(blocked=True, left_free=True, right_free=True, clears_left=False), M.LANE_CHANGE_RIGHT,
     False),
    ("keep_overtake_right_waits_until_it_clears", M.LANE_KEEP,
     x(blocked=True, right_free=True, clears_right=False), None, False),
    ("keep_route_change_needs_no_pass_clearance", M.LANE_KEEP,
     x(route_lane=-1, right_free=True, clears_right=False), M.LANE_CHANGE_RIGHT, False),
    # a pass starts only if it is over, the car back in its lane, before a vehicle coming
    # up behind in the lane it moves into (not braking) is nearer than the rear distance:
    # the car follows the vehicle ahead (or stops behind it) until that one has gone by
    ("keep_overtake_left_waits_for_a_faster_car_behind", M.LANE_KEEP,
     x(blocked=True, left_free=True, outruns_left=False), None, False),
    ("keep_overtake_right_when_only_it_outruns", M.LANE_KEEP,
     x(blocked=True, left_free=True, right_free=True, outruns_left=False),
     M.LANE_CHANGE_RIGHT, False),
    ("keep_overtake_right_waits_for_a_faster_car_behind", M.LANE_KEEP,
     x(blocked=True, right_free=True, outruns_right=False), None, False),
    ("keep_route_change_needs_no_outrun", M.LANE_KEEP,
     x(route_lane=1, left_free=True, outruns_left=False), M.LANE_CHANGE_LEFT, False),
    ("keep_right_needs_no_outrun", M.LANE_KEEP,
     x(right_free=True, right_clear=True, outruns_right=False), M.LANE_CHANGE_RIGHT, False),
    ("keep_free_not_blocked", M.LANE_KEEP, x(left_free=True, right_free=True), None, False),
    ("keep_overtake_not_allowed", M.LANE_KEEP, x(overtake=False, blocked=True, left_free=True),
     None, False),
    ("keep_overtake_waits_keep_time", M.LANE_KEEP,
     x(since=T - 2.0, blocked=True, left_free=True), None, False),
    # LANE_KEEP -> keep right (after a pass: the right lane free and nothing slower in it)
    ("keep_right", M.LANE_KEEP, x(right_free=True, right_clear=True), M.LANE_CHANGE_RIGHT,
     False),
    ("keep_right_not_into_a_slower_car", M.LANE_KEEP, x(right_free=True), None, False),
    ("keep_right_waits_for_the_gap", M.LANE_KEEP, x(right_clear=True), None, False),
    ("keep_right_waits_keep_time", M.LANE_KEEP,
     x(since=T - 2.0, right_free=True, right_clear=True), None, False),
    ("keep_right_yields_to_a_faster_car_behind_at_once", M.LANE_KEEP,
     x(since=T - 0.1, right_free=True, right_clear=True, yield_behind=True),
     M.LANE_CHANGE_RIGHT, False),
    ("keep_right_yielding_still_waits_for_the_gap", M.LANE_KEEP,
     x(since=T - 0.1, right_clear=True, yield_behind=True), None, False),
    ("keep_right_only_where_lane_changes_are_allowed", M.LANE_KEEP,
     x(overtake=False, right_free=True, right_clear=True), None, False),
    ("keep_right_not_before_a_route_change", M.LANE_KEEP,
     x(route_lane=1, right_free=True, right_clear=True), None, False),
    ("keep_right_not_while_pulling_over_elsewhere", M.LANE_KEEP,
     x(turn=Turn.LEFT, right_free=True, right_clear=True), M.TURN_LEFT, False),
    # LANE_KEEP -> a pass through the oncoming lane (a road with one lane each way)
    ("keep_overtake_oncoming", M.LANE_KEEP, x(blocked=True, oncoming_pass=True),
     M.LANE_CHANGE_LEFT, False),
    ("keep_oncoming_waits_until_it_is_safe", M.LANE_KEEP, x(blocked=True), None, False),
    ("keep_oncoming_only_when_blocked", M.LANE_KEEP, x(oncoming_pass=True), None, False),
    ("keep_oncoming_waits_keep_time", M.LANE_KEEP,
     x(since=T - 2.0, blocked=True, oncoming_pass=True), None, False),
    ("keep_oncoming_not_allowed", M.LANE_KEEP,
     x(overtake=False, blocked=True, oncoming_pass=True), None, False),
    ("keep_oncoming_after_a_lane_beside", M.LANE_KEEP,
     x(blocked=True, left_free=True, oncoming_pass=True), M.LANE_CHANGE_LEFT, False),
    # LANE_KEEP in the oncoming lane -> back into the own lane at once, nothing else
    ("oncoming_back", M.LANE_KEEP, x(in_oncoming=True, back_free=True), M.LANE_CHANGE_RIGHT,
     False),
    ("oncoming_back_needs_no_keep_time", M.LANE_KEEP,
     x(since=T - 0.1, in_oncoming=True, back_free=True), M.LANE_CHANGE_RIGHT, False),
    ("oncoming_back_before_a_flat_tyre", M.LANE_KEEP,
     x(in_oncoming=True, back_free=True, pull_over=True, right_free=True),
     M.LANE_CHANGE_RIGHT, False),
    ("oncoming_stays_until_back_is_free", M.LANE_KEEP, x(in_oncoming=True), None, False),
    ("oncoming_no_other_pass", M.LANE_KEEP,
     x(in_oncoming=True, blocked=True, left_free=True, oncoming_pass=True), None, False),
    ("oncoming_no_keep_right_row", M.LANE_KEEP,
     x(in_oncoming=True, right_free=True, right_clear=True), None, False),
    # LANE_CHANGE_* -> LANE_KEEP
    ("left_done", M.LANE_CHANGE_LEFT, x(change_done=True), M.LANE_KEEP, False),
    ("left_abort", M.LANE_CHANGE_LEFT, x(target_free=False), M.LANE_KEEP, True),
    ("oncoming_abort_before_alongside", M.LANE_CHANGE_LEFT,
     x(target_free=False, oncoming_pass=True), M.LANE_KEEP, True),
    ("left_committed_no_abort", M.LANE_CHANGE_LEFT, x(target_free=False, committed=True), None,
     False),
    ("left_stays", M.LANE_CHANGE_LEFT, x(blocked=True, left_free=True), None, False),
    ("right_done", M.LANE_CHANGE_RIGHT, x(change_done=True), M.LANE_KEEP, False),
    ("right_abort", M.LANE_CHANGE_RIGHT, x(target_free=False), M.LANE_KEEP, True),
    ("right_committed_no_abort", M.LANE_CHANGE_RIGHT, x(target_free=False, committed=True),
     None, False),
    ("right_stays", M.LANE_CHANGE_RIGHT, x(), None, False),
    ("change_ignores_turns", M.LANE_CHANGE_RIGHT, x(turn=Turn.LEFT), None, False),
    # turns -> LANE_KEEP
    ("turn_right_done", M.TURN_RIGHT, x(turn_done=True), M.LANE_KEEP, False),
    ("turn_left_done", M.TURN_LEFT, x(turn_done=True), M.LANE_KEEP, False),
    ("u_turn_done", M.U_TURN, x(turn_done=True), M.LANE_KEEP, False),
    ("turn_stays", M.TURN_LEFT, x(blocked=True, left_free=True, turn=Turn.LEFT), None, False),
    ("u_turn_stays", M.U_TURN, x(), None, False),
]


ABORT = next(row for row in TABLE.rows if row.when.startswith("abort"))


@pytest.mark.parametrize(("name", "state", "inp", "expected", "abort"), TABLE_CASES,
                         ids=[r[0] for r in TABLE_CASES])
def test_transition_table(name: str, state: Motion, inp: MotionInput, expected: Motion | None,
                          abort: bool) -> None:
    change = transition(state, inp, P)
    assert (change.to if change else None) is expected, name
    if change is not None:
        assert change.reason
        assert (fired_row(TABLE, state, inp, P) is ABORT) is abort
        assert abort is (not inp.change_done and state is not M.LANE_KEEP
                         and state in {M.LANE_CHANGE_LEFT, M.LANE_CHANGE_RIGHT})


def test_the_cases_walk_every_row_of_the_data() -> None:
    cases = [(state, inp, expected) for _, state, inp, expected, _ in TABLE_CASES]
    assert unwalked_rows(TABLE, cases, lambda _: P) == []


def test_the_module_doc_shows_the_table_of_the_data() -> None:
    assert doc_shows_table(motion, TABLE)


def test_every_transition_of_the_table_has_a_row() -> None:
    pairs = {(row[1], row[3]) for row in TABLE_CASES if row[3] is not None}
    assert pairs == {
        (M.LANE_KEEP, M.TURN_RIGHT), (M.LANE_KEEP, M.TURN_LEFT), (M.LANE_KEEP, M.U_TURN),
        (M.LANE_KEEP, M.LANE_CHANGE_LEFT), (M.LANE_KEEP, M.LANE_CHANGE_RIGHT),
        (M.LANE_CHANGE_LEFT, M.LANE_KEEP), (M.LANE_CHANGE_RIGHT, M.LANE_KEEP),
        (M.TURN_RIGHT, M.LANE_KEEP), (M.TURN_LEFT, M.LANE_KEEP), (M.U_TURN, M.LANE_KEEP),
    }
    assert {row[1] for row in TABLE_CASES} == set(Motion)
    assert pairs == TABLE.edges


@pytest.mark.parametrize(("state", "inp", "passing"), [
    (M.LANE_KEEP, x(blocked=True, left_free=True), True),  # overtake left
    (M.LANE_KEEP, x(blocked=True, right_free=True), True),  # overtake right
    (M.LANE_KEEP, x(blocked=True, oncoming_pass=True), True),  # through the oncoming lane
    (M.LANE_KEEP, x(in_oncoming=True, back_free=True), False),  # back from it
    (M.LANE_KEEP, x(route_lane=-1, right_free=True), False),  # the route's change
    (M.LANE_KEEP, x(pull_over=True, right_free=True), False),  # a flat tyre's
    (M.LANE_KEEP, x(right_free=True, right_clear=True), False),  # keeping right
    (M.LANE_KEEP, x(), False),  # no change
])
def test_a_change_to_pass_is_told_from_the_others(state: Motion, inp: MotionInput,
                                                  passing: bool) -> None:
    assert is_pass(state, inp, MotionParams()) is passing
