"""The hazard lights' machine: on for good after a flat tyre; on during a minimum-risk stop
in lane after a sensor fault, off when it is over."""

from __future__ import annotations

from planner.fsm import hazard
from planner.fsm.hazard import TABLE, HazardInput, HazardLights, transition
from tests.planner.fsm.tables import doc_shows_table, unwalked_rows

OFF, ON = HazardLights.OFF, HazardLights.ON
STOP = "no LiDAR scan for 0.6 s"
CASES = [
    (OFF, HazardInput(), None),
    (OFF, HazardInput(flat=True), ON),
    (OFF, HazardInput(flat=True, stop=STOP), ON),  # the flat tyre's row first
    (OFF, HazardInput(stop=STOP), ON),
    (ON, HazardInput(flat=True), None),  # a flat tyre: on for good
    (ON, HazardInput(flat=True, stop=None), None),
    (ON, HazardInput(stop=STOP), None),
    (ON, HazardInput(), OFF),  # the stop is over: the car resumes
]


def test_the_lights_go_on_with_a_flat_tyre_or_a_minimum_risk_stop() -> None:
    for state, x, expected in CASES:
        change = transition(state, x)
        assert (change.to if change else None) is expected, (state, x)
    change = transition(OFF, HazardInput(flat=True))
    assert change is not None and change.reason == "flat tyre"
    change = transition(OFF, HazardInput(stop=STOP))
    assert change is not None and change.reason == f"minimum-risk stop: {STOP}"


def test_the_cases_walk_every_row_of_the_data() -> None:
    assert unwalked_rows(TABLE, CASES, lambda _: None) == []


def test_the_module_doc_shows_the_table_of_the_data() -> None:
    assert doc_shows_table(hazard, TABLE)
