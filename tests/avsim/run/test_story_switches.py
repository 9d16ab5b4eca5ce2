"""Which acts and events an OpenSCENARIO file switches off by its own configuration
(`avsim.run.story_switches`), and the `story` verdict on them: off by a parameter or
variable nothing changes is not applicable; an act the run should have started still
fails."""

from __future__ import annotations

import pytest

from avsim.criteria.story import Story
from avsim.run.story_switches import (
    COLLISION_REACTION,
    collision_reactions,
    reacts_to_collision,
    switched_off,
    switched_off_by,
)
from avsim.scenario.openscenario.conditions import (
    CollisionCondition,
    Condition,
    ConditionGroup,
    ConditionKind,
    ParameterCondition,
    SimulationTimeCondition,
    Trigger,
    VariableCondition,
)
from avsim.scenario.openscenario.parameters import ParamValue
from avsim.scenario.openscenario.storyboard import (
    Act,
    Action,
    Actors,
    Event,
    Maneuver,
    ManeuverGroup,
    Storyboard,
)
from avsim.scenario.openscenario.storyboard import Story as OscStory
from avsim.scenario.openscenario.variables import SetValue, VariableAction, VariableDeclaration

PARAMETERS: dict[str, ParamValue] = {"isCCRbraking": False, "Ego_speed_kph": 50.0}
VARIABLES = (VariableDeclaration("phase", "int", 0),)


def cond(kind: ConditionKind) -> Condition:
    return Condition("c", 0.0, "none", None, kind)


def trigger(*groups: tuple[ConditionKind, ...]) -> Trigger:
    return Trigger(tuple(ConditionGroup(tuple(cond(k) for k in g)) for g in groups))


BRAKING = ParameterCondition("isCCRbraking", "true", "equalTo")  # false at the defaults
NOT_BRAKING = ParameterCondition("isCCRbraking", "false", "equalTo")  # true
FAST = ParameterCondition("Ego_speed_kph", "40", "greaterThan")  # true
PHASE = VariableCondition("phase", "1", "equalTo")  # false at the start
LATE = SimulationTimeCondition(3.0, "greaterThan")  # depends on the run
SET_PHASE = VariableAction("variable", "phase", "int", SetValue(1))


@pytest.mark.parametrize(("trig", "why"), [
    (trigger((BRAKING,)), "switched off by parameter isCCRbraking"),
    (trigger((NOT_BRAKING,)), None),  # true: it starts at once
    (trigger((FAST, BRAKING)), "switched off by parameter Ego_speed_kph, parameter "
     "isCCRbraking"),  # AND: one false value keeps it off
    (trigger((BRAKING,), (PHASE,)), "switched off by parameter isCCRbraking, variable phase"),
    (trigger((BRAKING,), (FAST,)), None),  # OR: a group holds
    (trigger((BRAKING, LATE)), None),  # a time: the run decides (counted)
    (trigger((LATE,)), None),
    (trigger((ParameterCondition("undeclared", "1", "equalTo"),)), None),  # not a setting
    (None, None),  # no trigger: starts with its parent
    (Trigger(()), None),  # no group: never fires, but not by configuration
])
def test_a_trigger_of_fixed_parameter_values_that_are_false_is_switched_off(
        trig: Trigger | None, why: str | None) -> None:
    fixed = frozenset({("parameter", "isCCRbraking"), ("parameter", "Ego_speed_kph"),
                       ("variable", "phase")})
    assert switched_off_by(trig, fixed, PARAMETERS, {"phase": 0}) == why


def board(act_trigger: Trigger | None, event_trigger: Trigger | None = None,
          init: tuple[VariableAction, ...] = (),
          story_sets: tuple[VariableAction, ...] = ()) -> Storyboard:
    actions = (Action("brake", VariableAction("variable", "other", "int", SetValue(2))),)
    events = [Event("e", "overwrite", 1, actions, event_trigger)]
    events += [Event(f"s{i}", "overwrite", 1, (Action(f"set{i}", a),), None)
               for i, a in enumerate(story_sets)]
    group = ManeuverGroup("g", 1, Actors(("ego",), False), (Maneuver("m", tuple(events)),))
    return Storyboard((), (OscStory("s", (Act("act", (group,), act_trigger, None),)),),
                      None, init)


@pytest.mark.parametrize(("storyboard", "off"), [
    (board(trigger((BRAKING,))), {"brake": "switched off by parameter isCCRbraking"}),
    (board(None, trigger((BRAKING,))), {"brake": "switched off by parameter isCCRbraking"}),
    (board(trigger((LATE,))), {}),  # the run starts it, or `story` fails
    (board(trigger((PHASE,))), {"brake": "switched off by variable phase"}),
    (board(trigger((PHASE,)), story_sets=(SET_PHASE,)), {}),  # the story sets it
    (board(trigger((PHASE,)), init=(SET_PHASE,)), {}),  # the Init sets it
    (board(trigger((BRAKING,)), init=(VariableAction("parameter", "isCCRbraking", "boolean",
                                                     SetValue(True)),)), {}),
])
def test_the_actions_of_an_act_or_event_switched_off_by_the_file(storyboard: Storyboard,
                                                                 off: dict[str, str]) -> None:
    assert switched_off(storyboard, PARAMETERS, VARIABLES) == off


@pytest.mark.parametrize(("labels", "off", "fired", "passed", "note"), [
    # CCRs: the CCRb act off by its parameter, the rest played
    (("storyboard.go",), {"storyboard.brake": "switched off by parameter isCCRbraking"},
     {"storyboard.go"}, True,
     "not applicable: switched off by parameter isCCRbraking (storyboard.brake)"),
    # an act the run should have started (a time to collision) that never did: fails
    (("storyboard.go", "storyboard.brake"), {}, {"storyboard.go"}, False,
     "never fired: storyboard.brake"),
    (("storyboard.go",), {"storyboard.brake": "switched off by parameter isCCRbraking"},
     set(), False, "never fired: storyboard.go; not applicable: switched off by parameter "
     "isCCRbraking (storyboard.brake)"),
    (("storyboard.go",), {}, {"storyboard.go"}, True, None),
])
def test_story_does_not_count_actions_the_file_switches_off(
        labels: tuple[str, ...], off: dict[str, str], fired: set[str], passed: bool,
        note: str | None) -> None:
    story = Story(labels, off)
    story.fired = frozenset(fired)
    result = story.result()
    assert (result.passed, result.note) == (passed, note)


def test_story_with_every_action_switched_off_is_not_applicable_and_says_why() -> None:
    result = Story((), {"storyboard.brake": "switched off by parameter isCCRbraking"}).result()
    assert result.note == ("not applicable: switched off by parameter isCCRbraking "
                           "(storyboard.brake)")
    assert result.passed is None  # not applicable


HIT = CollisionCondition("GVT", None)


@pytest.mark.parametrize(("trig", "reacts"), [
    (trigger((HIT,)), True),  # the NCAP files' AtCollision: records the outcome
    (trigger((HIT,), (HIT,)), True),
    (trigger((HIT, LATE)), False),  # a time too: part of the story
    (trigger((LATE,)), False),
    (None, False),
    (Trigger(()), False),
])
def test_an_act_or_event_started_only_by_a_collision_reacts_to_it(trig: Trigger | None,
                                                                  reacts: bool) -> None:
    assert (reacts_to_collision(trig) == COLLISION_REACTION) is reacts
    assert collision_reactions(board(None, trig)) == ({"brake": COLLISION_REACTION}
                                                      if reacts else {})


def test_story_lists_only_the_actions_not_required_that_did_not_fire() -> None:
    """A collision happened: its reaction fired and is no 'not applicable'."""
    story = Story(("storyboard.go",), {"storyboard.hit": COLLISION_REACTION})
    story.fired = frozenset({"storyboard.go", "storyboard.hit"})
    assert (story.result().passed, story.result().note) == (True, None)
