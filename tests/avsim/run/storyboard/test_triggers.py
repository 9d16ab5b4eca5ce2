"""Edges and delays of conditions, and the OR-of-ANDs of triggers."""

from __future__ import annotations

import pytest

from avsim.run.storyboard.triggers import ConditionWatch, TriggerWatch, edge_value
from avsim.scenario.openscenario.conditions import (
    Edge,
    SimulationTimeCondition,
    SpeedCondition,
    Trigger,
)
from tests.avsim.run.storyboard.helpers import condition, context, entity, snapshot, trigger

CTX = context()
DT = 0.1


def values(watch: ConditionWatch | TriggerWatch, speeds: list[float],
           dt: float = DT) -> list[bool]:
    """The watch's answers at t = 0, dt, 2 dt ... with Ego at these speeds."""
    return [watch.update(snapshot(entity("Ego", speed=v), t=k * dt), CTX)
            for k, v in enumerate(speeds)]


FAST = SpeedCondition(10.0, "greaterThan")
SPEEDS = [20.0, 5.0, 20.0, 20.0, 5.0, 5.0]


@pytest.mark.parametrize(("edge", "expected"), [
    ("none", [True, False, True, True, False, False]),
    ("rising", [False, False, True, False, False, False]),
    ("falling", [False, True, False, False, True, False]),
    ("risingOrFalling", [False, True, True, False, True, False]),
])
def test_edges(edge: Edge, expected: list[bool]) -> None:
    """The first evaluation has no previous value: an edge is false there (esmini)."""
    watch = ConditionWatch(condition(FAST, edge=edge, entities=("Ego",)))
    assert values(watch, SPEEDS) == expected


def test_edge_value_table() -> None:
    assert edge_value("rising", True, None) is False
    assert edge_value("falling", False, None) is False
    assert edge_value("risingOrFalling", True, None) is False
    assert edge_value("none", True, None) is True


def test_a_rising_edge_with_a_10_s_delay_fires_10_s_after() -> None:
    """As the ALKS stop triggers: rising at t = 2.0 passes on at t = 12.0, one step only."""
    watch = ConditionWatch(condition(SimulationTimeCondition(2.0, "greaterOrEqual"),
                                     edge="rising", delay=10.0))
    fired = [k * DT for k in range(200)
             if watch.update(snapshot(t=k * DT), CTX)]
    assert fired == [pytest.approx(12.0)]


def test_a_level_condition_with_a_delay_follows_its_value_late() -> None:
    watch = ConditionWatch(condition(FAST, delay=0.2, entities=("Ego",)))
    assert values(watch, SPEEDS) == [False, False, True, False, True, True]


def test_a_delay_with_an_irregular_step_takes_the_latest_value_before() -> None:
    watch = ConditionWatch(condition(SimulationTimeCondition(1.0, "greaterOrEqual"),
                                     edge="rising", delay=1.0))
    answers = [(t, watch.update(snapshot(t=t), CTX)) for t in (0.0, 0.7, 1.3, 1.9, 2.4, 3.1)]
    assert answers == [(0.0, False), (0.7, False), (1.3, False), (1.9, False), (2.4, True),
                       (3.1, False)]


def test_reset_forgets_the_previous_value() -> None:
    watch = ConditionWatch(condition(FAST, edge="rising", entities=("Ego",)))
    assert values(watch, [5.0, 20.0]) == [False, True]
    watch.reset()
    assert values(watch, [20.0]) == [False]


def test_trigger_or_of_and_groups() -> None:
    fast = condition(FAST, entities=("Ego",))
    late = condition(SimulationTimeCondition(1.0, "greaterOrEqual"))
    early = condition(SimulationTimeCondition(0.5, "lessThan"))
    watch = TriggerWatch(trigger((fast, late), (early,)))
    answers = [watch.update(snapshot(entity("Ego", speed=v), t=t), CTX)
               for t, v in ((0.0, 0.0), (0.6, 20.0), (1.0, 5.0), (1.1, 20.0))]
    assert answers == [True, False, False, True]
    assert watch.triggering_entities() == ("Ego",)


def test_an_empty_trigger_never_fires_and_none_fires_at_once() -> None:
    assert not TriggerWatch(Trigger(())).update(snapshot(), CTX)
    assert TriggerWatch(None).update(snapshot(), CTX)
