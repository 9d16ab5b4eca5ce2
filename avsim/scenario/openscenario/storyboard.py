"""The storyboard: Init actions, stories, acts, maneuver groups, maneuvers, events, actions."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Literal

from avsim.scenario.openscenario.actions import PrivateAction
from avsim.scenario.openscenario.conditions import Trigger
from avsim.scenario.openscenario.global_actions import GlobalAction

Priority = Literal["overwrite", "override", "skip", "parallel"]  # override is 1.2's overwrite


@dataclass(frozen=True, slots=True)
class InitAction:
    entity: str
    action: PrivateAction


@dataclass(frozen=True, slots=True)
class Action:
    """An event's action: a private action applies to each actor of its maneuver group, a
    global action (environment, variables) to the storyboard's state."""

    name: str
    private_action: PrivateAction | GlobalAction  # the PrivateAction or GlobalAction held


@dataclass(frozen=True, slots=True)
class Event:
    name: str
    priority: Priority
    maximum_execution_count: int  # default 1
    actions: tuple[Action, ...]
    start_trigger: Trigger | None  # None: starts with its maneuver


@dataclass(frozen=True, slots=True)
class Maneuver:
    name: str
    events: tuple[Event, ...]


@dataclass(frozen=True, slots=True)
class Actors:
    entities: tuple[str, ...]
    select_triggering_entities: bool


@dataclass(frozen=True, slots=True)
class ManeuverGroup:
    name: str
    maximum_execution_count: int
    actors: Actors
    maneuvers: tuple[Maneuver, ...]  # catalog references resolved


@dataclass(frozen=True, slots=True)
class Act:
    name: str
    maneuver_groups: tuple[ManeuverGroup, ...]
    start_trigger: Trigger | None  # required in 1.0/1.1, optional in 1.2
    stop_trigger: Trigger | None


@dataclass(frozen=True, slots=True)
class Story:
    name: str
    acts: tuple[Act, ...]


@dataclass(frozen=True, slots=True)
class Storyboard:
    init: tuple[InitAction, ...]
    stories: tuple[Story, ...]
    stop_trigger: Trigger | None
    init_global: tuple[GlobalAction, ...] = ()  # the Init's GlobalActions, in order

    def story_actions(self) -> Iterator[tuple[ManeuverGroup, Action]]:
        """Every action of the stories with its maneuver group, in the file's order."""
        for story in self.stories:
            for act in story.acts:
                for group in act.maneuver_groups:
                    for maneuver in group.maneuvers:
                        for event in maneuver.events:
                            for action in event.actions:
                                yield group, action
