"""The lane-source FSM: every transition of its table, and the ones that must not happen."""

from __future__ import annotations

import pytest

from planner.fsm import lane_source
from planner.fsm.lane_source import (
    TABLE,
    LaneSource,
    LaneSourceInput,
    LaneSourceParams,
    transition,
)
from tests.planner.fsm.tables import doc_shows_table, unwalked_rows

P = LaneSourceParams()
S = LaneSource

# (state, t, confidence, since) -> next state (None: stay); near a junction: JUNCTION_TABLE
TABLE_CASES = [
    # ACQUIRING
    (S.ACQUIRING, 0.2, P.acquire, 0.0, S.CAMERA),
    (S.ACQUIRING, 0.2, P.acquire - 0.01, 0.0, None),
    (S.ACQUIRING, P.acquire_time, 0.0, 0.0, S.MAP_HOLD),
    (S.ACQUIRING, P.acquire_time - 0.01, 0.0, 0.0, None),
    # CAMERA: hysteresis between lose and acquire
    (S.CAMERA, 5.0, P.lose - 0.01, 1.0, S.MAP_HOLD),
    (S.CAMERA, 5.0, P.lose, 1.0, None),
    (S.CAMERA, 5.0, 0.9, 1.0, None),
    (S.CAMERA, 500.0, 0.9, 1.0, None),
    # MAP_HOLD
    (S.MAP_HOLD, 3.0, P.acquire, 2.0, S.CAMERA),
    (S.MAP_HOLD, 3.0, 0.4, 2.0, None),  # between lose and acquire: not yet back
    (S.MAP_HOLD, 2.0 + P.stop_after, 0.0, 2.0, S.STOP_IN_LANE),
    (S.MAP_HOLD, 2.0 + P.stop_after - 0.01, 0.0, 2.0, None),
    # STOP_IN_LANE
    (S.STOP_IN_LANE, 20.0, P.acquire, 9.0, S.CAMERA),
    (S.STOP_IN_LANE, 200.0, 0.1, 9.0, None),
    # MAP (no camera in this stack): never changes
    (S.MAP, 100.0, 1.0, 0.0, None),
    (S.MAP, 100.0, 0.0, 0.0, None),
]

# (state, confidence, the camera's lane is another than the lane kept) -> next state
OTHER_LANE_TABLE = [
    (S.CAMERA, 0.9, True, S.ACQUIRING),  # the path is the map's: the source says so
    (S.CAMERA, P.lose - 0.01, True, S.MAP_HOLD),  # lost first
    (S.ONE_LINE, 0.2, True, S.ACQUIRING),
    (S.ACQUIRING, 0.9, True, None),  # a good estimate, but of another lane
    (S.MAP_HOLD, 0.9, True, None),
    (S.STOP_IN_LANE, 0.9, True, None),
    (S.JUNCTION, 0.9, True, S.ACQUIRING),
    (S.MAP, 0.9, True, None),
]


# (state, confidence, lines seen, age of the last measurement) -> next state: one-line lane
# keeping (a line hidden, a dashed line's gaps), and a camera that sees no line at all
ONE_LINE_TABLE = [
    (S.CAMERA, P.lose - 0.01, 1, 0.0, S.ONE_LINE),  # a truck hides the left line
    (S.CAMERA, P.lose - 0.01, 2, 0.4, S.ONE_LINE),  # two lines, too little of them to measure
    (S.CAMERA, P.lose - 0.01, 1, P.dead_reckon_time, S.MAP_HOLD),  # not measured for too long
    (S.CAMERA, P.lose - 0.01, 0, 0.3, S.MAP_HOLD),  # no line at all (a black camera)
    (S.CAMERA, P.lose, 1, 0.0, None),
    (S.ONE_LINE, 0.1, 1, P.dead_reckon_time - 0.01, None),  # dead-reckoning a dash's gap
    (S.ONE_LINE, 0.0, 0, 0.5, None),  # a frame without a line, within the dead reckoning
    (S.ONE_LINE, 0.45, 1, 0.0, None),  # one line well seen: still one line
    (S.ONE_LINE, 0.1, 1, P.dead_reckon_time, S.MAP_HOLD),
    (S.ONE_LINE, P.acquire, 2, 0.0, S.CAMERA),
    (S.ACQUIRING, 0.45, 1, 0.0, None),  # a lane is acquired on both lines only
    (S.MAP_HOLD, 0.45, 1, 0.0, None),
]


# (state, confidence, how a camera fault was noticed) -> next state: a faulty camera's lane
# is not kept, nor taken back, until its frames are sound
FAULT = "camera frame carries no information (grey spread 0.0 < 2)"
CAMERA_FAULT_TABLE = [
    (S.CAMERA, 0.9, FAULT, S.MAP_HOLD),
    (S.ONE_LINE, 0.2, FAULT, S.MAP_HOLD),
    (S.ACQUIRING, 0.9, FAULT, S.MAP_HOLD),
    (S.MAP_HOLD, 0.9, FAULT, None),  # a stale good estimate: not taken back
    (S.STOP_IN_LANE, 0.9, FAULT, None),
    (S.JUNCTION, 0.9, FAULT, S.ACQUIRING),  # past the junction: looking, not on the camera
    (S.MAP, 0.9, FAULT, None),
    (S.MAP_HOLD, 0.9, None, S.CAMERA),  # sound again: the lane is found
]


# (state, confidence, near a junction) -> next state
JUNCTION_TABLE = [
    (S.CAMERA, 0.9, True, S.JUNCTION),
    (S.MAP_HOLD, 0.0, True, S.JUNCTION),
    (S.STOP_IN_LANE, 0.0, True, S.JUNCTION),
    (S.ACQUIRING, 0.9, True, S.JUNCTION),
    (S.ONE_LINE, 0.2, True, S.JUNCTION),
    (S.MAP, 0.0, True, None),  # no camera: the map anyway
    (S.JUNCTION, 0.0, True, None),
    (S.JUNCTION, 0.9, True, None),  # lines seen inside: still the map's turn path
    (S.JUNCTION, P.acquire, False, S.CAMERA),
    (S.JUNCTION, P.acquire - 0.01, False, S.ACQUIRING),
]


@pytest.mark.parametrize(("state", "t", "confidence", "since", "expected"), TABLE_CASES)
def test_transition_table(state: LaneSource, t: float, confidence: float, since: float,
                          expected: LaneSource | None) -> None:
    change = transition(state, LaneSourceInput(t, confidence, since), P)
    assert (change.to if change else None) is expected
    if change is not None:
        assert change.reason


@pytest.mark.parametrize(("state", "confidence", "lines", "age", "expected"), ONE_LINE_TABLE)
def test_one_line_table(state: LaneSource, confidence: float, lines: int, age: float,
                        expected: LaneSource | None) -> None:
    change = transition(state, LaneSourceInput(100.0, confidence, 99.5, lines=lines, age=age), P)
    assert (change.to if change else None) is expected
    if change is not None:
        assert change.reason


@pytest.mark.parametrize(("state", "confidence", "junction", "expected"), JUNCTION_TABLE)
def test_junction_table(state: LaneSource, confidence: float, junction: bool,
                        expected: LaneSource | None) -> None:
    change = transition(state, LaneSourceInput(100.0, confidence, 99.0, junction), P)
    assert (change.to if change else None) is expected


@pytest.mark.parametrize(("state", "confidence", "other", "expected"), OTHER_LANE_TABLE)
def test_other_lane_table(state: LaneSource, confidence: float, other: bool,
                          expected: LaneSource | None) -> None:
    change = transition(state, LaneSourceInput(100.0, confidence, 99.5, other_lane=other), P)
    assert (change.to if change else None) is expected


@pytest.mark.parametrize(("state", "confidence", "fault", "expected"), CAMERA_FAULT_TABLE)
def test_camera_fault_table(state: LaneSource, confidence: float, fault: str | None,
                            expected: LaneSource | None) -> None:
    change = transition(state, LaneSourceInput(100.0, confidence, 99.5, camera_fault=fault), P)
    assert (change.to if change else None) is expected
    if change is not None and expected is S.MAP_HOLD:
        assert change.reason == f"{FAULT}: holding on the map"


# (seconds stood of the time in MAP_HOLD) -> next state: entered at 2 s, now 2 s +
# stop_after; standing (in a queue, the lines hidden by the car ahead) does not count
STANDING_TABLE = [
    (0.0, S.STOP_IN_LANE),
    (0.01, None),
    (P.stop_after, None),  # stood the whole time: holds on
]


@pytest.mark.parametrize(("standing", "expected"), STANDING_TABLE)
def test_standing_time_does_not_count_towards_the_stop_in_lane(
        standing: float, expected: LaneSource | None) -> None:
    x = LaneSourceInput(2.0 + P.stop_after, 0.0, 2.0, standing=standing)
    change = transition(S.MAP_HOLD, x, P)
    assert (change.to if change else None) is expected
    moved_on = LaneSourceInput(2.0 + P.stop_after + standing, 0.0, 2.0, standing=standing)
    again = transition(S.MAP_HOLD, moved_on, P)  # once it has moved stop_after in all
    assert again is not None and again.to is S.STOP_IN_LANE


def test_every_state_and_edge_of_the_table_is_covered() -> None:
    edges = {(row[0], row[4]) for row in TABLE_CASES if row[4] is not None}
    edges |= {(row[0], row[3]) for row in JUNCTION_TABLE if row[3] is not None}
    edges |= {(row[0], row[3]) for row in OTHER_LANE_TABLE if row[3] is not None}
    edges |= {(row[0], row[4]) for row in ONE_LINE_TABLE if row[4] is not None}
    assert edges == {(S.ACQUIRING, S.CAMERA), (S.ACQUIRING, S.MAP_HOLD),
                     (S.CAMERA, S.MAP_HOLD), (S.CAMERA, S.ACQUIRING), (S.MAP_HOLD, S.CAMERA),
                     (S.CAMERA, S.ONE_LINE), (S.ONE_LINE, S.CAMERA), (S.ONE_LINE, S.MAP_HOLD),
                     (S.ONE_LINE, S.ACQUIRING),
                     (S.MAP_HOLD, S.STOP_IN_LANE), (S.STOP_IN_LANE, S.CAMERA),
                     *((s, S.JUNCTION) for s in (S.CAMERA, S.MAP_HOLD, S.STOP_IN_LANE,
                                                 S.ACQUIRING, S.ONE_LINE)),
                     (S.JUNCTION, S.CAMERA), (S.JUNCTION, S.ACQUIRING)}
    assert {row[0] for row in TABLE_CASES} | {row[0] for row in JUNCTION_TABLE} | {
        row[0] for row in ONE_LINE_TABLE} == set(LaneSource)


def test_the_cases_walk_every_row_of_the_data() -> None:
    cases = [(state, LaneSourceInput(t, confidence, since), expected)
             for state, t, confidence, since, expected in TABLE_CASES]
    cases += [(state, LaneSourceInput(100.0, confidence, 99.0, junction), expected)
              for state, confidence, junction, expected in JUNCTION_TABLE]
    cases += [(state, LaneSourceInput(100.0, confidence, 99.5, other_lane=other), expected)
              for state, confidence, other, expected in OTHER_LANE_TABLE]
    cases += [(state, LaneSourceInput(100.0, confidence, 99.5, lines=lines, age=age), expected)
              for state, confidence, lines, age, expected in ONE_LINE_TABLE]
    cases += [(state, LaneSourceInput(100.0, confidence, 99.5, camera_fault=fault), expected)
              for state, confidence, fault, expected in CAMERA_FAULT_TABLE]
    assert unwalked_rows(TABLE, cases, lambda _: P) == []


def test_the_module_doc_shows_the_table_of_the_data() -> None:
    assert doc_shows_table(lane_source, TABLE)
