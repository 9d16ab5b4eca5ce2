"""The storyboard's elements at run time: one `Node` per story, act, maneuver group,
maneuver, event and action, with its state, its execution count and its triggers; built
from the typed model by `build`, and indexed by (element type, name) for the storyboard
element state conditions (`name_index`)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from avsim.run.storyboard.elements import ElementState
from avsim.run.storyboard.triggers import TriggerWatch
from avsim.scenario.openscenario.conditions import StoryboardElementStateCondition, Trigger
from avsim.scenario.openscenario.storyboard import (
    Act,
    Action,
    Event,
    Maneuver,
    ManeuverGroup,
    Story,
    Storyboard,
)


@dataclass(slots=True, eq=False)
class Node:
    """One storyboard element in one run (mutable: the runtime moves it)."""

    element_type: str  # story, act, maneuverGroup, maneuver, event, action
    name: str
    path: str  # "Story/Act/MG/Maneuver/Event/Action"
    parent: Node | None
    max_executions: int = 1  # maximumExecutionCount (events, maneuver groups), else 1
    start: TriggerWatch | None = None  # acts, events: the start trigger's watch
    stop: TriggerWatch | None = None  # acts: the stop trigger's watch
    event: Event | None = None  # events: the model element
    group: ManeuverGroup | None = None  # maneuver groups: the model element
    action: Action | None = None  # actions: the model element
    children: list[Node] = field(default_factory=list)
    state: ElementState = ElementState.STANDBY
    executions: int = 0  # starts since the node was (re)armed
    runs: int = 0  # starts over the whole run (actions: the id's suffix)

    def walk(self) -> Iterator[Node]:
        """This node and every node below it, depth first."""
        yield self
        for child in self.children:
            yield from child.walk()

    @property
    def action_id(self) -> str:
        """An action's id for its current execution: "<path>#<runs>"."""
        return f"{self.path}#{self.runs}"

    def ancestor(self, element_type: str) -> Node:
        node: Node | None = self
        while node is not None and node.element_type != element_type:
            node = node.parent
        if node is None:
            raise ValueError(f"{self.path} has no {element_type} above it")
        return node


def _add(parent: Node | None, node: Node) -> Node:
    if parent is not None:
        parent.children.append(node)
    return node


def _start_watch(trigger: Trigger | None) -> TriggerWatch:
    """A start trigger's watch: one without a condition group (`<StartTrigger/>`) starts
    its element at once, as none does (esmini's default for start triggers; an empty stop
    trigger never fires)."""
    return TriggerWatch(trigger if trigger is not None and trigger.groups else None)


def _event(parent: Node, e: Event) -> Node:
    node = _add(parent, Node("event", e.name, f"{parent.path}/{e.name}", parent,
                             max_executions=e.maximum_execution_count,
                             start=_start_watch(e.start_trigger), event=e))
    for a in e.actions:
        _add(node, Node("action", a.name, f"{node.path}/{a.name}", node, action=a))
    return node


def _maneuver(parent: Node, m: Maneuver) -> Node:
    node = _add(parent, Node("maneuver", m.name, f"{parent.path}/{m.name}", parent))
    for e in m.events:
        _event(node, e)
    return node


def _group(parent: Node, mg: ManeuverGroup) -> Node:
    node = _add(parent, Node("maneuverGroup", mg.name, f"{parent.path}/{mg.name}", parent,
                             max_executions=mg.maximum_execution_count, group=mg))
    for m in mg.maneuvers:
        _maneuver(node, m)
    return node


def _act(parent: Node, a: Act) -> Node:
    stop = None if a.stop_trigger is None else TriggerWatch(a.stop_trigger)
    node = _add(parent, Node("act", a.name, f"{parent.path}/{a.name}", parent,
                             start=_start_watch(a.start_trigger), stop=stop))
    for mg in a.maneuver_groups:
        _group(node, mg)
    return node


def build(stories: tuple[Story, ...]) -> tuple[Node, ...]:
    """The run-time tree of every story, all in standbyState."""
    roots = []
    for s in stories:
        root = Node("story", s.name, s.name, None)
        for a in s.acts:
            _act(root, a)
        roots.append(root)
    return tuple(roots)


def _triggers(storyboard: Storyboard) -> Iterator[Trigger]:
    if storyboard.stop_trigger is not None:
        yield storyboard.stop_trigger
    for story in storyboard.stories:
        for act in story.acts:
            yield from (t for t in (act.start_trigger, act.stop_trigger) if t is not None)
            for mg in act.maneuver_groups:
                for m in mg.maneuvers:
                    yield from (e.start_trigger for e in m.events if e.start_trigger)


def name_index(storyboard: Storyboard,
               roots: tuple[Node, ...]) -> dict[tuple[str, str], Node]:
    """(element type, name) -> node. Raises ValueError when a storyboard element state
    condition refers to a name that no element, or more than one, of its type has."""
    index: dict[tuple[str, str], list[Node]] = {}
    for node in (n for root in roots for n in root.walk()):
        index.setdefault((node.element_type, node.name), []).append(node)
    for trigger in _triggers(storyboard):
        for group in trigger.groups:
            for c in group.conditions:
                if isinstance(c.kind, StoryboardElementStateCondition):
                    _check_reference(c.name, c.kind, index)
    return {key: nodes[0] for key, nodes in index.items() if len(nodes) == 1}


def _check_reference(condition: str, c: StoryboardElementStateCondition,
                     index: dict[tuple[str, str], list[Node]]) -> None:
    key = (c.element_type, c.element_ref.split("::")[-1])
    nodes = index.get(key, [])
    if len(nodes) != 1:
        found = ", ".join(n.path for n in nodes) or "none"
        raise ValueError(f"condition {condition}: {c.element_type} {c.element_ref} must name "
                         f"exactly one element (found: {found})")
