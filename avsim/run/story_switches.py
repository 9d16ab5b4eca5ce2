"""Which parts of an OpenSCENARIO storyboard the file itself switches off by configuration.

A file may hold acts for several variants of its test and start each by a parameter: the
Euro NCAP CCR file starts its CCRb act by a ParameterCondition on ``isCCRbraking`` and
plays CCRs or CCRm with it false. Such an act is not the situation failing to happen: it
is off by the file's own setting, and its actions are no part of the run's story.

An Act or Event is switched off when its start trigger is made only of ParameterConditions
and VariableConditions (any number of groups, every condition of each), on parameters and
variables that no action of the storyboard sets or modifies (Init or story: a
ParameterAction / VariableAction), and the trigger is false with their values at the start
(the resolved parameters, the variables' declared values). Those values never change in
the run, so the trigger never fires. A trigger with any other condition (a time, a
distance, a time to collision, another element's state) depends on the run: its act is
counted, and fails `story` if it never fires.

One kind of run-dependent trigger is no stimulus either: an Act or Event started only by
CollisionConditions reacts to a collision (the Euro NCAP files' ``AtCollision`` event sets
their ``collisionDetected`` variable, for the StopTrigger). It records the test's outcome:
a collision avoided is no part of the story missing (`collision_reactions`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping

from avsim.run.storyboard.rules import value_holds
from avsim.scenario.openscenario.conditions import (
    CollisionCondition,
    Condition,
    ParameterCondition,
    Trigger,
    VariableCondition,
)
from avsim.scenario.openscenario.parameters import ParamValue
from avsim.scenario.openscenario.storyboard import Storyboard
from avsim.scenario.openscenario.variables import VariableAction, VariableDeclaration

Setting = tuple[str, str]  # ("parameter" or "variable", its name)


def _set_by_actions(board: Storyboard) -> frozenset[Setting]:
    """The parameters and variables some action of `board` sets or modifies."""
    actions = [*board.init_global, *(a.private_action for _, a in board.story_actions())]
    return frozenset((a.target, a.name) for a in actions if isinstance(a, VariableAction))


def _setting(c: Condition) -> Setting | None:
    kind = c.kind
    if isinstance(kind, ParameterCondition):
        return "parameter", kind.parameter
    if isinstance(kind, VariableCondition):
        return "variable", kind.variable
    return None


def _holds(c: Condition, parameters: Mapping[str, ParamValue],
           variables: Mapping[str, ParamValue]) -> bool:
    kind = c.kind
    if isinstance(kind, ParameterCondition):
        return value_holds(kind.parameter, kind.rule, kind.value, parameters)
    assert isinstance(kind, VariableCondition)
    return value_holds(kind.variable, kind.rule, kind.value, variables)


def switched_off_by(trigger: Trigger | None, fixed: frozenset[Setting],
                    parameters: Mapping[str, ParamValue],
                    variables: Mapping[str, ParamValue]) -> str | None:
    """Why `trigger` never fires by configuration ("switched off by parameter X"), or None
    when it may fire (module doc). `fixed`: the settings no action changes."""
    if trigger is None or not trigger.groups:
        return None
    conditions = [c for g in trigger.groups for c in g.conditions]
    settings = [_setting(c) for c in conditions]
    if not conditions or any(s is None or s not in fixed for s in settings):
        return None
    if any(g.conditions and all(_holds(c, parameters, variables) for c in g.conditions)
           for g in trigger.groups):
        return None
    names = dict.fromkeys(f"{kind} {name}" for kind, name in (s for s in settings if s))
    return "switched off by " + ", ".join(names)


def switched_off(board: Storyboard, parameters: Mapping[str, ParamValue],
                 variables: tuple[VariableDeclaration, ...] = ()) -> dict[str, str]:
    """Action name -> why it never starts, for each action of an Act or Event that the file
    switches off by configuration (module doc)."""
    initial = {v.name: v.value for v in variables}
    fixed = frozenset(
        [("parameter", n) for n in parameters] + [("variable", n) for n in initial]
    ) - _set_by_actions(board)
    out: dict[str, str] = {}
    for why, name in _off_actions(board, fixed, parameters, initial):
        out.setdefault(name, why)
    return out


def _off_actions(board: Storyboard, fixed: frozenset[Setting],
                 parameters: Mapping[str, ParamValue],
                 variables: Mapping[str, ParamValue]) -> Iterator[tuple[str, str]]:
    def off(trigger: Trigger | None) -> str | None:
        return switched_off_by(trigger, fixed, parameters, variables)
    yield from _judged_actions(board, off)


COLLISION_REACTION = "reacts to a collision (CollisionCondition), which did not happen"


def reacts_to_collision(trigger: Trigger | None) -> str | None:
    """`COLLISION_REACTION` when `trigger` is made only of CollisionConditions, else None."""
    if trigger is None or not trigger.groups:
        return None
    conditions = [c for g in trigger.groups for c in g.conditions]
    if conditions and all(isinstance(c.kind, CollisionCondition) for c in conditions):
        return COLLISION_REACTION
    return None


def collision_reactions(board: Storyboard) -> dict[str, str]:
    """Action name -> `COLLISION_REACTION`, for each action of an Act or Event started only
    by collisions (module doc)."""
    out: dict[str, str] = {}
    for why, name in _judged_actions(board, reacts_to_collision):
        out.setdefault(name, why)
    return out


def _judged_actions(board: Storyboard, judge: Callable[[Trigger | None], str | None],
                    ) -> Iterator[tuple[str, str]]:
    """(why, action name) for each action whose Act's or Event's start trigger `judge`
    gives a reason for."""
    for story in board.stories:
        for act in story.acts:
            act_why = judge(act.start_trigger)
            for group in act.maneuver_groups:
                for maneuver in group.maneuvers:
                    for event in maneuver.events:
                        why = act_why or judge(event.start_trigger)
                        if why is not None:
                            yield from ((why, a.name) for a in event.actions)
