"""The run's story: each scripted action and event, and when it fired.

Two kinds of scenario script their story. A YAML scenario's actors' actions and ego
events fire in the world (`ScriptedStory`: `World.action_fired_at`, `event_fired_at`). An
OpenSCENARIO file's storyboard is played by the director (`StoryboardStory`): its entries
are the storyboard's actions (by name) and its StopTrigger, fired when they first started;
the actions of an Act or Event the file switches off by configuration, or that only react
to a collision, are optional, with the reason (`avsim.run.story_switches`).
The `story` criterion judges the labels fired; the result lists the entries.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from avsim.criteria.story import story_label
from avsim.run.story_switches import collision_reactions, switched_off
from avsim.run.storyboard.director import Director
from avsim.scenario.scenario import Scenario
from world.world import World

STOP_TRIGGER = "StopTrigger"  # the storyboard entry of the file's stop trigger


@dataclass(frozen=True, slots=True)
class StoryEntry:
    """A scripted action of an actor (`actor` its id, `index` in its actions), an ego event
    (`actor` None, `index` in the scenario's events), or an OpenSCENARIO storyboard element
    (`element` its name, `actor` None, `index` its order), and when it fired."""

    actor: str | None
    index: int
    kind: str  # the action's or event's kind (`speed`, `lane_change`, `flat_tire`, ...)
    optional: bool  # the run may end without it
    fired_at: float | None  # [s] None: it never fired
    element: str | None = None  # an OpenSCENARIO storyboard element's name
    off: str | None = None  # why the file switches it off by configuration (then optional;
    #   `avsim.run.story_switches`), None: it is part of the story

    @property
    def label(self) -> str:
        if self.element is not None:
            return f"storyboard.{self.element}"
        return story_label(self.actor, self.index)


def kind_of(thing: object) -> str:
    """A spec's kind as the file names it: `LaneChangeAction` -> `lane_change`."""
    name = type(thing).__name__.removesuffix("Action")
    return "".join(f"_{c.lower()}" if c.isupper() else c for c in name).lstrip("_")


class ScriptedStory:
    """A YAML scenario's story: its actors' actions and ego events (module doc)."""

    def __init__(self, scenario: Scenario, world: World) -> None:
        spec = scenario.world
        self.world = world
        actions = [StoryEntry(a.id, i, kind_of(x.action), x.optional, None)
                   for a in spec.actors for i, x in enumerate(a.actions)]
        events = [StoryEntry(None, i, kind_of(e.event), e.optional, None)
                  for i, e in enumerate(spec.events)]
        self.entries = tuple(actions + events)
        self.fired: frozenset[str] = frozenset()  # the labels fired so far

    def update(self) -> None:
        """The labels fired so far (a new set only on a change)."""
        w = self.world
        count = len(w.action_fired_at) + sum(t is not None for t in w.event_fired_at)
        if count != len(self.fired):
            self.fired = frozenset(
                [story_label(a, i) for a, i in w.action_fired_at]
                + [story_label(None, i) for i, t in enumerate(w.event_fired_at)
                   if t is not None])

    def now(self) -> tuple[StoryEntry, ...]:
        """The entries with the times they fired."""
        w = self.world
        return tuple(StoryEntry(
            e.actor, e.index, e.kind, e.optional,
            w.action_fired_at.get((e.actor, e.index)) if e.actor is not None
            else w.event_fired_at[e.index]) for e in self.entries)


class StoryboardStory:
    """An OpenSCENARIO storyboard's story: every action of its stories, then the StopTrigger
    (module doc)."""

    def __init__(self, director: Director) -> None:
        self.director = director
        board = director.program.scenario.storyboard
        osc = director.program.scenario
        off = collision_reactions(board) | switched_off(board, osc.parameters, osc.variables)
        names = [(action.name, kind_of(action.private_action))
                 for _, action in board.story_actions()]
        if board.stop_trigger is not None:
            names.append((STOP_TRIGGER, "stop_trigger"))
        self.entries = tuple(StoryEntry(None, i, kind, name in off, None, element=name,
                                        off=off.get(name))
                             for i, (name, kind) in enumerate(names))
        self.fired: frozenset[str] = frozenset()
        self._at: dict[str, float] = {}

    def update(self) -> None:
        history = self.director.runtime.history()
        for t, element_type, name, transition in history:
            if element_type == "action" and transition == "startTransition":
                self._at.setdefault(name, t)
        if self.director.ended and self.director.ended_at is not None:
            self._at.setdefault(STOP_TRIGGER, self.director.ended_at)
        if len(self._at) != len(self.fired):
            self.fired = frozenset(f"storyboard.{name}" for name in self._at)

    def now(self) -> tuple[StoryEntry, ...]:
        return tuple(replace(e, fired_at=self._at.get(e.element or "")) for e in self.entries)
