"""The storyboard at run time (`StoryRuntime`): which actions start and stop at each step.

Each `step(snap)` evaluates, in this order:
1. the storyboard's stop trigger (every step; none: never): when it fires every element
   still in standby or running is stopped and the run has ended;
2. each story (started at the first step), each of its acts: a standby act's start trigger
   (none: it starts at once) starts it with all its maneuver groups and their maneuvers; a
   running act's stop trigger stops it and everything in it; a re-armed maneuver group
   (maximumExecutionCount) starts again at once;
3. in each running maneuver, each standby event's start trigger (none: it starts at once)
   starts it with all its actions, by its priority: overwrite / override stop the other
   running events of the maneuver first; skip is not started (a skipTransition) while
   another event of the maneuver runs; parallel starts alongside;
4. the actions the runtime completes itself (`INSTANT`: controller assignment and
   activation, teleport, entity actions: add, delete, visibility, lights) end at once;
   global actions (`GLOBAL`: environment, variables, parameters) change the runtime's
   `story_state` (`state.StoryState`) when they start, are not passed on to the world,
   and end at once (an EntityAction is: its entity is the started action's). The Init's
   global actions are played on the state at t = 0, before the first trigger check.
A trigger is evaluated only while its element waits for it (standby under a running
parent; an act's stop trigger while the act runs), as esmini does. An action ends when the
world says so (`action_done`); an element ends when all its children completed (an event:
all its actions; a maneuver: its events; a maneuver group: its maneuvers; an act: its
groups; a story: its acts). An event or group that ends with executions left goes back to
standby with its children re-armed (states reset without transitions recorded, trigger
histories cleared). An element stopped is complete for good (no re-run), and a skipped
event counts no execution (recorded each step its trigger fires while blocked).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass

from avsim.run.storyboard.conditions import ConditionContext, Resolver, no_resolver
from avsim.run.storyboard.elements import (
    ElementState,
    TransitionKind,
    TransitionRecord,
    TransitionRequest,
    transition,
)
from avsim.run.storyboard.snapshot import Snapshot
from avsim.run.storyboard.state import StoryState
from avsim.run.storyboard.state_conditions import Lanes, no_lanes
from avsim.run.storyboard.tree import Node, build, name_index
from avsim.run.storyboard.triggers import TriggerWatch
from avsim.scenario.openscenario.actions import (
    ActivateControllerAction,
    AssignControllerAction,
    OverrideControllerValueAction,
    PrivateAction,
    TeleportAction,
)
from avsim.scenario.openscenario.entity_actions import (
    AddEntityAction,
    DeleteEntityAction,
    EntityAction,
    LightStateAction,
    VisibilityAction,
)
from avsim.scenario.openscenario.environment import EnvironmentAction
from avsim.scenario.openscenario.parameters import ParamValue
from avsim.scenario.openscenario.storyboard import Storyboard
from avsim.scenario.openscenario.variables import VariableAction, VariableDeclaration

INSTANT = (ActivateControllerAction, AssignControllerAction, OverrideControllerValueAction,
           TeleportAction, AddEntityAction, DeleteEntityAction, VisibilityAction,
           LightStateAction)  # end at once
GLOBAL = (EnvironmentAction, VariableAction)  # played on the runtime's state, end at once
S, K = ElementState, TransitionKind


@dataclass(frozen=True, slots=True)
class StartedAction:
    """An action to start on the world now."""

    action_id: str  # "Story/Act/MG/Maneuver/Event/Action#<n>", n = its n-th start
    name: str
    entities: tuple[str, ...]  # the group's actors (and the triggering entities if selected);
    #   an EntityAction's: its entity
    action: PrivateAction | EntityAction


@dataclass(frozen=True, slots=True)
class StepResult:
    time: float  # [s]
    started: tuple[StartedAction, ...]
    stopped: tuple[str, ...]  # ids of running actions to stop on the world now
    ended: bool  # the storyboard's stop trigger has fired (now or before)


class _LiveStates(Mapping[tuple[str, str], ElementState]):
    """The states now of the elements with a unique (type, name)."""

    def __init__(self, index: dict[tuple[str, str], Node]) -> None:
        self._index = index

    def __getitem__(self, key: tuple[str, str]) -> ElementState:
        return self._index[key].state

    def __iter__(self) -> Iterator[tuple[str, str]]:
        return iter(self._index)

    def __len__(self) -> int:
        return len(self._index)


class StoryRuntime:
    """One run of a storyboard (module doc). `parameters` are the scenario's values and
    `variables` its declared variables (their values at the start: the state that parameter
    and variable conditions read); `resolve` places a Position (distance and reach
    conditions); `lanes` counts the route's lanes at a station (clearance conditions)."""

    def __init__(self, storyboard: Storyboard, parameters: Mapping[str, ParamValue],
                 resolve: Resolver = no_resolver,
                 variables: tuple[VariableDeclaration, ...] = (),
                 lanes: Lanes = no_lanes) -> None:
        self.storyboard = storyboard
        self.stories = build(storyboard.stories)
        index = name_index(storyboard, self.stories)
        self._log: list[TransitionRecord] = []
        self.story_state = StoryState(parameters, variables)
        for init in storyboard.init_global:  # no EntityAction: refused in Init at load
            if isinstance(init, GLOBAL):
                self.story_state.apply(init, 0.0)
        self._ctx = ConditionContext(self.story_state.parameters, _LiveStates(index),
                                     self._log, 0, resolve, self.story_state, lanes)
        self._stop = None if storyboard.stop_trigger is None else TriggerWatch(
            storyboard.stop_trigger)
        self._actions = {n.path: n for root in self.stories for n in root.walk()
                         if n.element_type == "action"}
        self._started: list[StartedAction] = []
        self._stopped: list[str] = []
        self._instant: list[Node] = []
        self._t = 0.0
        self.ended = False

    # --- the public API -----------------------------------------------------------------

    def step(self, snap: Snapshot) -> StepResult:
        """Advance to `snap.time`: the actions to start and to stop now."""
        self._t = snap.time
        self._started, self._stopped, self._instant = [], [], []
        if not self.ended and self._stop is not None and self._stop.update(snap, self._ctx):
            self.ended = True
            for root in self.stories:
                self._stop_tree(root)
        if not self.ended:
            for story in self.stories:
                self._run_story(story, snap)
            for node in self._instant:
                self._end(node)
        return StepResult(snap.time, tuple(self._started), tuple(self._stopped), self.ended)

    def action_done(self, action_id: str, t: float) -> None:
        """The world reports the action reached its goal at `t` [s]: it ends (and what it
        completes with it). Ignored unless that execution of the action is running. The
        director reports after the `step` of the same time, so conditions on the end see it
        at the next step (esmini's order: triggers, then the actions)."""
        path, _, _n = action_id.rpartition("#")
        node = self._actions.get(path)
        if node is None:
            raise KeyError(f"no action {action_id!r}")
        if node.action_id == action_id and node.state is S.RUNNING:
            self._t = t
            self._end(node)

    def history(self) -> list[tuple[float, str, str, str]]:
        """Every transition so far: (t [s], element type, name, transition)."""
        return [(r.t, r.element_type, r.name, r.transition.value) for r in self._log]

    def state(self, element_type: str, name: str) -> ElementState:
        """The state now of the element of this type and (unique) name."""
        nodes = [n for root in self.stories for n in root.walk()
                 if (n.element_type, n.name) == (element_type, name)]
        if len(nodes) != 1:
            raise KeyError(f"{element_type} {name}: {len(nodes)} elements of that name")
        return nodes[0].state

    # --- transitions ---------------------------------------------------------------------

    def _apply(self, node: Node, kind: TransitionKind) -> bool:
        change = transition(node.state, TransitionRequest(
            kind, node.executions >= node.max_executions))
        if change is None:
            return False
        node.state = change[0]
        self._log.append(TransitionRecord(self._t, node.element_type, node.name, change[1],
                                          change[0]))
        return True

    def _start(self, node: Node, entities: tuple[str, ...] = ()) -> None:
        node.executions += 1
        node.runs += 1
        if not self._apply(node, K.START):
            node.executions -= 1
            node.runs -= 1
            return
        _STARTS[node.element_type](self, node, entities)
        if node.element_type != "action" and not node.children:
            self._end(node)  # nothing inside: complete at once

    def _end(self, node: Node) -> None:
        if not self._apply(node, K.END):
            return
        if node.state is S.STANDBY:  # re-armed
            self._rearm(node)
        if node.parent is not None:
            self._check_done(node.parent)

    def _check_done(self, node: Node) -> None:
        if node.state is S.RUNNING and all(c.state is S.COMPLETE for c in node.children):
            self._end(node)

    def _rearm(self, node: Node) -> None:
        for child in node.walk():
            if child is not node:
                child.state, child.executions = S.STANDBY, 0
            for watch in (child.start, child.stop):
                if watch is not None:
                    watch.reset()

    def _stop_tree(self, node: Node) -> None:
        """Stop `node` and every element below it still standby or running."""
        was_running = node.state is S.RUNNING
        if not self._apply(node, K.STOP):
            return
        if node.element_type == "action" and was_running:
            self._stopped.append(node.action_id)
        for child in node.children:
            self._stop_tree(child)

    # --- what starts with what -----------------------------------------------------------

    def _start_children(self, node: Node, _entities: tuple[str, ...]) -> None:
        for child in node.children:
            self._start(child)

    def _start_event(self, node: Node, entities: tuple[str, ...]) -> None:
        group = node.ancestor("maneuverGroup").group
        assert group is not None
        actors = group.actors.entities
        if group.actors.select_triggering_entities:
            actors = tuple(dict.fromkeys((*actors, *entities)))
        for child in node.children:
            self._start(child, actors)

    def _start_action(self, node: Node, entities: tuple[str, ...]) -> None:
        assert node.action is not None
        action = node.action.private_action
        if isinstance(action, GLOBAL):
            self.story_state.apply(action, self._t)
            self._instant.append(node)
            return
        if isinstance(action, AddEntityAction | DeleteEntityAction):
            entities = (action.entity,)
        self._started.append(StartedAction(node.action_id, node.name, entities, action))
        if isinstance(action, INSTANT):
            self._instant.append(node)

    def _nothing(self, node: Node, entities: tuple[str, ...]) -> None:
        """Its children wait for their own triggers (a story's acts, a maneuver's events)."""

    # --- one step ------------------------------------------------------------------------

    def _run_story(self, story: Node, snap: Snapshot) -> None:
        if story.state is S.STANDBY:
            self._start(story)
        if story.state is not S.RUNNING:
            return
        for act in story.children:
            self._run_act(act, snap)

    def _run_act(self, act: Node, snap: Snapshot) -> None:
        assert act.start is not None
        if act.state is S.STANDBY and act.start.update(snap, self._ctx):
            self._start(act)
        if act.state is not S.RUNNING:
            return
        if act.stop is not None and act.stop.update(snap, self._ctx):
            self._stop_tree(act)
            self._check_done(act.ancestor("story"))
            return
        for group in act.children:
            if group.state is S.STANDBY:
                self._start(group)
            for maneuver in group.children:
                self._run_maneuver(maneuver, snap)

    def _run_maneuver(self, maneuver: Node, snap: Snapshot) -> None:
        for event in maneuver.children:
            if maneuver.state is not S.RUNNING:
                return
            assert event.start is not None
            if event.state is S.STANDBY and event.start.update(snap, self._ctx):
                self._fire(maneuver, event, event.start.triggering_entities())

    def _fire(self, maneuver: Node, event: Node, entities: tuple[str, ...]) -> None:
        assert event.event is not None
        others = [e for e in maneuver.children if e is not event and e.state is S.RUNNING]
        priority = event.event.priority
        if priority == "skip" and others:
            self._apply(event, K.SKIP)
            return
        if priority in ("overwrite", "override"):
            for other in others:
                self._stop_tree(other)
        self._start(event, entities)


_STARTS = {
    "story": StoryRuntime._nothing,
    "act": StoryRuntime._start_children,
    "maneuverGroup": StoryRuntime._start_children,
    "maneuver": StoryRuntime._nothing,
    "event": StoryRuntime._start_event,
    "action": StoryRuntime._start_action,
}
