"""The storyboard runtime on small hand-made storyboards: starts, completion, priorities,
execution counts, stop triggers and the element state conditions."""

from __future__ import annotations

import pytest

from avsim.run.storyboard.elements import ElementState
from avsim.run.storyboard.runtime import StepResult, StoryRuntime
from avsim.scenario.openscenario.conditions import (
    SpeedCondition,
    StoryboardElementStateCondition,
    Trigger,
)
from avsim.scenario.openscenario.storyboard import Storyboard
from tests.avsim.run.storyboard.helpers import (
    at_time,
    condition,
    entity,
    event,
    snapshot,
    storyboard,
    trigger,
)

PATH = "S/Act/G/M"


def run(board: Storyboard) -> StoryRuntime:
    return StoryRuntime(board, {})


def step(rt: StoryRuntime, t: float, speed: float = 0.0) -> StepResult:
    return rt.step(snapshot(entity("Ego", speed=speed), entity("Car"), t=t))


def started(result: StepResult) -> list[str]:
    return [a.action_id for a in result.started]


def state_of(name: str, kind: str, state: str) -> Trigger:
    return trigger((condition(StoryboardElementStateCondition(kind, name, state)),))


def test_an_event_starts_on_its_trigger_and_everything_completes_with_its_action() -> None:
    rt = run(storyboard(event("E", at_time(1.0))))
    assert step(rt, 0.0).started == ()
    result = step(rt, 1.0)
    assert started(result) == [f"{PATH}/E/EA#1"]
    assert result.started[0].entities == ("Ego",)
    assert result.started[0].name == "EA"
    rt.action_done(f"{PATH}/E/EA#1", 1.5)
    assert [h[1:] for h in rt.history()] == [
        ("story", "S", "startTransition"), ("act", "Act", "startTransition"),
        ("maneuverGroup", "G", "startTransition"), ("maneuver", "M", "startTransition"),
        ("event", "E", "startTransition"), ("action", "EA", "startTransition"),
        ("action", "EA", "endTransition"), ("event", "E", "endTransition"),
        ("maneuver", "M", "endTransition"), ("maneuverGroup", "G", "endTransition"),
        ("act", "Act", "endTransition"), ("story", "S", "endTransition"),
    ]
    assert [h[0] for h in rt.history()] == [0.0] * 4 + [1.0] * 2 + [1.5] * 6
    assert rt.state("story", "S") is ElementState.COMPLETE
    assert not step(rt, 2.0).ended  # no stop trigger: never ends


def test_an_event_completes_when_all_its_actions_did() -> None:
    rt = run(storyboard(event("E", None, actions=("A", "B"))))
    assert started(step(rt, 0.0)) == [f"{PATH}/E/EA#1", f"{PATH}/E/EB#1"]
    rt.action_done(f"{PATH}/E/EA#1", 0.5)
    assert rt.state("event", "E") is ElementState.RUNNING
    rt.action_done(f"{PATH}/E/EB#1", 0.7)
    assert rt.state("event", "E") is ElementState.COMPLETE


def test_instant_actions_complete_at_once() -> None:
    rt = run(storyboard(event("E", None, instant=True)))
    result = step(rt, 0.0)
    assert started(result) == [f"{PATH}/E/EA#1"]
    assert rt.state("story", "S") is ElementState.COMPLETE


def test_overwrite_stops_the_running_event() -> None:
    rt = run(storyboard(event("E1", None), event("E2", at_time(1.0))))
    assert started(step(rt, 0.0)) == [f"{PATH}/E1/E1A#1"]
    result = step(rt, 1.0)
    assert result.stopped == (f"{PATH}/E1/E1A#1",)
    assert started(result) == [f"{PATH}/E2/E2A#1"]
    assert (1.0, "event", "E1", "stopTransition") in rt.history()
    assert rt.state("event", "E1") is ElementState.COMPLETE
    rt.action_done(f"{PATH}/E1/E1A#1", 1.2)  # stale: ignored
    rt.action_done(f"{PATH}/E2/E2A#1", 1.5)
    assert rt.state("maneuver", "M") is ElementState.COMPLETE


def test_skip_waits_while_another_event_runs() -> None:
    rt = run(storyboard(event("E1", None), event("E2", at_time(1.0), priority="skip")))
    step(rt, 0.0)
    result = step(rt, 1.0)
    assert result.started == () and result.stopped == ()
    assert (1.0, "event", "E2", "skipTransition") in rt.history()
    rt.action_done(f"{PATH}/E1/E1A#1", 1.1)
    assert started(step(rt, 1.2)) == [f"{PATH}/E2/E2A#1"]


def test_parallel_runs_alongside() -> None:
    rt = run(storyboard(event("E1", None), event("E2", at_time(1.0), priority="parallel")))
    step(rt, 0.0)
    result = step(rt, 1.0)
    assert result.stopped == ()
    assert started(result) == [f"{PATH}/E2/E2A#1"]


def test_maximum_execution_count_re_arms_the_event() -> None:
    rt = run(storyboard(event("E", at_time(0.0), count=3), event("F", at_time(99.0))))
    ids = []
    for k in range(6):
        ids += started(step(rt, k * 0.1))
        for i in ids:
            rt.action_done(i, k * 0.1)
    assert ids == [f"{PATH}/E/EA#1", f"{PATH}/E/EA#2", f"{PATH}/E/EA#3"]
    assert rt.state("event", "E") is ElementState.COMPLETE
    ends = [h for h in rt.history() if h[1:] == ("event", "E", "endTransition")]
    assert len(ends) == 3


def test_maximum_execution_count_of_a_group_runs_it_again() -> None:
    rt = run(storyboard(event("E", None), group_count=2))
    assert started(step(rt, 0.0)) == [f"{PATH}/E/EA#1"]
    rt.action_done(f"{PATH}/E/EA#1", 0.05)
    assert rt.state("maneuverGroup", "G") is ElementState.STANDBY
    assert started(step(rt, 0.1)) == [f"{PATH}/E/EA#2"]
    rt.action_done(f"{PATH}/E/EA#2", 0.15)
    assert rt.state("act", "Act") is ElementState.COMPLETE


def test_an_act_waits_for_its_start_trigger() -> None:
    rt = run(storyboard(event("E", None), act_start=at_time(2.0)))
    assert step(rt, 1.0).started == ()
    assert started(step(rt, 2.0)) == [f"{PATH}/E/EA#1"]


def test_an_events_trigger_is_evaluated_only_once_its_act_runs() -> None:
    """A rising edge is first evaluated when the event starts waiting: a condition already
    true then does not rise (the first evaluation has no previous value)."""
    fast = condition(SpeedCondition(10.0, "greaterThan"), edge="rising", entities=("Ego",))
    rt = run(storyboard(event("E", trigger((fast,))), act_start=at_time(2.0)))
    step(rt, 0.0, speed=5.0)
    assert step(rt, 1.0, speed=20.0).started == ()  # the act waits: not evaluated
    assert step(rt, 2.0, speed=20.0).started == ()  # first evaluation: no rise
    assert step(rt, 2.1, speed=5.0).started == ()
    assert started(step(rt, 2.2, speed=20.0)) == [f"{PATH}/E/EA#1"]


def test_an_acts_stop_trigger_stops_everything_in_it() -> None:
    rt = run(storyboard(event("E1", None), event("E2", at_time(50.0)), act_stop=at_time(1.0)))
    step(rt, 0.0)
    result = step(rt, 1.0)
    assert result.stopped == (f"{PATH}/E1/E1A#1",)
    assert not result.ended
    stops = [h[1:3] for h in rt.history() if h[3] == "stopTransition"]
    assert stops == [("act", "Act"), ("maneuverGroup", "G"), ("maneuver", "M"),
                     ("event", "E1"), ("action", "E1A"), ("event", "E2"), ("action", "E2A")]
    assert rt.state("story", "S") is ElementState.COMPLETE


def test_the_storyboards_stop_trigger_ends_the_run() -> None:
    rt = run(storyboard(event("E", None), stop=at_time(1.0)))
    step(rt, 0.0)
    result = step(rt, 1.0)
    assert result.ended and result.stopped == (f"{PATH}/E/EA#1",)
    later = step(rt, 1.1)
    assert later.ended and later.started == () and later.stopped == ()


def test_an_event_starts_on_an_actions_end_transition() -> None:
    first = event("E1", None)
    second = event("E2", state_of("E1A", "action", "endTransition"), priority="parallel")
    rt = run(storyboard(first, second))
    step(rt, 0.0)
    assert step(rt, 0.1).started == ()
    rt.action_done(f"{PATH}/E1/E1A#1", 0.15)
    assert started(step(rt, 0.2)) == [f"{PATH}/E2/E2A#1"]


def test_the_stop_trigger_on_an_actions_complete_state() -> None:
    board = storyboard(event("E", None), stop=state_of("EA", "action", "completeState"))
    rt = run(board)
    assert not step(rt, 0.0).ended
    rt.action_done(f"{PATH}/E/EA#1", 0.05)
    assert step(rt, 0.1).ended


def test_select_triggering_entities_adds_them_to_the_actors() -> None:
    fast = condition(SpeedCondition(1.0, "greaterThan"), entities=("Ego", "Car"))
    rt = run(storyboard(event("E", trigger((fast,))), actors=("Car",), select=True))
    step(rt, 0.0)
    result = step(rt, 0.1, speed=5.0)
    assert result.started[0].entities == ("Car", "Ego")


def test_an_ambiguous_reference_is_refused() -> None:
    board = storyboard(event("E", None), event("E", None),
                       stop=state_of("E", "event", "completeState"))
    with pytest.raises(ValueError, match="exactly one element"):
        run(board)


def test_an_unknown_action_id_is_refused() -> None:
    rt = run(storyboard(event("E", None)))
    with pytest.raises(KeyError):
        rt.action_done("S/nothing#1", 0.0)
