"""The sensing machine: a lost LiDAR makes a minimum-risk stop in lane, a faulty GNSS slows
the car down, and each resumes when its sensor is sound again."""

from __future__ import annotations

import pytest

from planner.fsm import sensing
from planner.fsm.sensing import TABLE, Sensing, SensingInput, SensingParams, transition
from tests.planner.fsm.tables import doc_shows_table, unwalked_rows

P = SensingParams()
S = Sensing
LIDAR = "no LiDAR scan for 0.6 s"
GNSS = "no valid GNSS fix for 3.1 s"
OCCLUDED = "45% of the camera frame dark and featureless (partly occluded)"
CASES = [
    (S.NOMINAL, SensingInput(), None),
    (S.NOMINAL, SensingInput(lidar=LIDAR), S.MINIMUM_RISK),
    (S.NOMINAL, SensingInput(lidar=LIDAR, gnss=GNSS), S.MINIMUM_RISK),  # the stop first
    (S.NOMINAL, SensingInput(gnss=GNSS), S.DEGRADED),
    (S.NOMINAL, SensingInput(occlusion=OCCLUDED), S.DEGRADED),
    (S.DEGRADED, SensingInput(gnss=GNSS), None),
    (S.DEGRADED, SensingInput(occlusion=OCCLUDED), None),
    (S.DEGRADED, SensingInput(lidar=LIDAR, gnss=GNSS), S.MINIMUM_RISK),
    (S.DEGRADED, SensingInput(), S.NOMINAL),
    (S.MINIMUM_RISK, SensingInput(lidar=LIDAR), None),
    (S.MINIMUM_RISK, SensingInput(lidar=LIDAR, gnss=GNSS), None),
    (S.MINIMUM_RISK, SensingInput(gnss=GNSS), S.DEGRADED),
    (S.MINIMUM_RISK, SensingInput(occlusion=OCCLUDED), S.DEGRADED),
    (S.MINIMUM_RISK, SensingInput(), S.NOMINAL),
]


@pytest.mark.parametrize(("state", "x", "expected"), CASES)
def test_transition_table(state: Sensing, x: SensingInput, expected: Sensing | None) -> None:
    change = transition(state, x, P)
    assert (change.to if change else None) is expected
    if change is not None:
        assert change.reason


def test_each_change_says_how_the_fault_was_noticed() -> None:
    change = transition(S.NOMINAL, SensingInput(lidar=LIDAR), P)
    assert change is not None and change.reason.startswith(LIDAR)
    change = transition(S.NOMINAL, SensingInput(gnss=GNSS), P)
    assert change is not None and change.reason.startswith(GNSS)
    change = transition(S.NOMINAL, SensingInput(occlusion=OCCLUDED), P)
    assert change is not None and change.reason.startswith(OCCLUDED)


def test_the_cases_walk_every_row_of_the_data() -> None:
    assert unwalked_rows(TABLE, CASES, lambda _: P) == []


def test_the_module_doc_shows_the_table_of_the_data() -> None:
    assert doc_shows_table(sensing, TABLE)
