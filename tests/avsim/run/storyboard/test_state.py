"""The storyboard's run-time state: variables and parameters set by actions and read by
conditions, the environment in effect and its time of day, and the record of changes."""

from __future__ import annotations

import pytest

from avsim.run.storyboard.elements import ElementState
from avsim.run.storyboard.runtime import StoryRuntime
from avsim.run.storyboard.state import StateChange, StoryState
from avsim.scenario.openscenario.conditions import (
    ParameterCondition,
    TimeOfDayCondition,
    VariableCondition,
)
from avsim.scenario.openscenario.environment import (
    Environment,
    EnvironmentAction,
    TimeOfDay,
    epoch_of,
)
from avsim.scenario.openscenario.global_actions import GlobalAction
from avsim.scenario.openscenario.parameters import ParameterType, ParamValue
from avsim.scenario.openscenario.storyboard import Action, Event
from avsim.scenario.openscenario.variables import (
    ModifyValue,
    SetValue,
    VariableAction,
    VariableDeclaration,
    apply_change,
)
from tests.avsim.run.storyboard.helpers import (
    at_time,
    condition,
    entity,
    snapshot,
    storyboard,
    trigger,
)

HIT = VariableDeclaration("hit", "boolean", False)
COUNT = VariableDeclaration("count", "int", 0)


def global_event(name: str, action: GlobalAction, start: object) -> Event:
    return Event(name, "parallel", 1, (Action(f"{name}A", action),), start)  # type: ignore[arg-type]


def step(rt: StoryRuntime, t: float) -> None:
    rt.step(snapshot(entity("Ego"), t=t))


def test_a_variable_set_by_one_event_starts_another() -> None:
    set_hit = VariableAction("variable", "hit", "boolean", SetValue(True))
    on_hit = trigger((condition(VariableCondition("hit", "true", "equalTo")),))
    board = storyboard(global_event("Set", set_hit, at_time(2.0)),
                       global_event("Seen", set_hit, on_hit))
    rt = StoryRuntime(board, {}, variables=(HIT,))
    for t in (0.0, 1.0, 1.9):
        step(rt, t)
    assert rt.state("event", "Seen") is ElementState.STANDBY
    step(rt, 2.0)
    assert rt.state("event", "Set") is ElementState.COMPLETE  # a global action ends at once
    assert rt.state("event", "Seen") is ElementState.COMPLETE  # seen in the same check
    assert rt.story_state.variables == {"hit": True}
    assert rt.story_state.changes[0] == StateChange(2.0, "variable", "hit", True)


def test_a_variable_condition_before_the_action_waits_for_the_next_check() -> None:
    add = VariableAction("variable", "count", "int", ModifyValue("add", 1.0))
    two = trigger((condition(VariableCondition("count", "2", "greaterOrEqual")),))
    board = storyboard(global_event("Seen", add, two), global_event("Add", add, None))
    rt = StoryRuntime(board, {}, variables=(COUNT,))
    step(rt, 0.0)
    assert rt.story_state.variables["count"] == 1
    assert rt.state("event", "Seen") is ElementState.STANDBY


def test_a_parameter_set_at_run_time_is_seen_by_parameter_conditions() -> None:
    set_speed = VariableAction("parameter", "Speed", "double", SetValue(30.0))
    fast = trigger((condition(ParameterCondition("Speed", "30", "equalTo")),))
    board = storyboard(global_event("Seen", set_speed, fast),
                       global_event("Set", set_speed, at_time(1.0)))
    rt = StoryRuntime(board, {"Speed": 10.0})
    step(rt, 0.0)
    assert rt.state("event", "Seen") is ElementState.STANDBY
    step(rt, 1.0)
    step(rt, 1.1)
    assert rt.state("event", "Seen") is ElementState.COMPLETE
    assert rt.story_state.parameters == {"Speed": 30.0}


def environment(animation: bool, at: str = "2020-06-01T21:59:00") -> EnvironmentAction:
    return EnvironmentAction(Environment("Night", TimeOfDay(animation, at, epoch_of(at)),
                                         None, None))


@pytest.mark.parametrize(("animation", "fires_at"), [(True, 60.0), (False, None)])
def test_the_time_of_day_advances_with_the_simulation_when_animated(
        animation: bool, fires_at: float | None) -> None:
    late = TimeOfDayCondition("2020-06-01T22:00:00", epoch_of("2020-06-01T22:00:00"),
                              "greaterOrEqual")
    set_count = VariableAction("variable", "count", "int", SetValue(1))
    board = storyboard(global_event("Late", set_count, trigger((condition(late),))))
    board = type(board)(board.init, board.stories, board.stop_trigger,
                        (environment(animation),))
    rt = StoryRuntime(board, {}, variables=(COUNT,))
    fired = None
    for k in range(0, 1300, 5):
        t = k / 10.0
        step(rt, t)
        if fired is None and rt.state("event", "Late") is ElementState.COMPLETE:
            fired = t
    assert fired == fires_at
    assert rt.story_state.changes[0].kind == "environment"
    assert rt.story_state.changes[0].t == 0.0


def test_no_time_of_day_no_time_of_day_condition() -> None:
    state = StoryState()
    assert state.time_of_day(10.0) is None
    state.apply(environment(True), 5.0)
    assert state.time_of_day(10.0) == epoch_of("2020-06-01T21:59:05")


@pytest.mark.parametrize(("vtype", "now", "change", "after"), [
    ("int", 7, SetValue(3), 3),
    ("int", 7, ModifyValue("add", 2.9), 9),  # the operand truncated, as esmini
    ("int", 7, ModifyValue("multiply", 0.5), 3),  # the product truncated
    ("int", -7, ModifyValue("multiply", 0.5), -3),
    ("double", 7.0, ModifyValue("add", 2.5), 9.5),
    ("double", 7.0, ModifyValue("multiply", 0.5), 3.5),
    ("boolean", False, SetValue(True), True),
    ("string", "a", SetValue("b"), "b"),
])
def test_changes(vtype: ParameterType, now: ParamValue, change: SetValue | ModifyValue,
                 after: ParamValue) -> None:
    result = apply_change(now, VariableAction("variable", "v", vtype, change))
    assert result == after and type(result) is type(after)
