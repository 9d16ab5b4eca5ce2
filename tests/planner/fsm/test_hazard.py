"""The hazard lights' machine: off until a flat tyre, then on for good."""

from __future__ import annotations

from planner.fsm import hazard
from planner.fsm.hazard import TABLE, HazardLights, transition
from tests.planner.fsm.tables import doc_shows_table, unwalked_rows

OFF, ON = HazardLights.OFF, HazardLights.ON
CASES = [(OFF, False, None), (OFF, True, ON), (ON, False, None), (ON, True, None)]


def test_the_lights_go_on_with_a_flat_tyre_and_stay_on() -> None:
    for state, flat, expected in CASES:
        change = transition(state, flat)
        assert (change.to if change else None) is expected
    change = transition(OFF, True)
    assert change is not None and change.reason == "flat tyre"


def test_the_cases_walk_every_row_of_the_data() -> None:
    assert unwalked_rows(TABLE, CASES, lambda _: None) == []


def test_the_module_doc_shows_the_table_of_the_data() -> None:
    assert doc_shows_table(hazard, TABLE)
