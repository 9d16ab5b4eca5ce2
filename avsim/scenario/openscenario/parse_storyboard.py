"""Reading the Storyboard: Init, Stories, Acts, ManeuverGroups (maneuvers inline or from a
ManeuverCatalog), Events, Actions, triggers."""

from __future__ import annotations

from dataclasses import replace

from avsim.scenario.openscenario.attributes import unsupported
from avsim.scenario.openscenario.context import Context
from avsim.scenario.openscenario.global_actions import GlobalAction
from avsim.scenario.openscenario.parse_actions import parse_private_action
from avsim.scenario.openscenario.parse_conditions import parse_trigger
from avsim.scenario.openscenario.parse_global import parse_global_action
from avsim.scenario.openscenario.storyboard import (
    Act,
    Action,
    Actors,
    Event,
    InitAction,
    Maneuver,
    ManeuverGroup,
    Story,
    Storyboard,
)
from avsim.scenario.openscenario.xmlread import Node

PRIORITIES = ("overwrite", "override", "skip", "parallel")


def parse_init(node: Node | None, ctx: Context) -> tuple[InitAction, ...]:
    if node is None:
        return ()
    actions: list[InitAction] = []
    for child in node.need("Actions").children:
        if child.tag == "GlobalAction":
            continue  # `parse_init_global`
        if child.tag != "Private":
            raise unsupported(child)
        entity = ctx.entity_ref(child)
        actions.extend(
            InitAction(entity, parse_private_action(pa, ctx)) for pa in child.all("PrivateAction")
        )
    return tuple(actions)


def parse_init_global(node: Node | None, ctx: Context) -> tuple[GlobalAction, ...]:
    """The Init's GlobalActions, in the file's order."""
    if node is None:
        return ()
    found = []
    for child in node.need("Actions").children:
        if child.tag != "GlobalAction":
            continue
        if child.child("EntityAction") is not None:  # Init's entities are its Private ones
            raise child.error("EntityAction in Init: not supported (an entity the Init "
                              "places is in the world from the start)")
        found.append(parse_global_action(child, ctx))
    return tuple(found)


def parse_action(node: Node, ctx: Context) -> Action:
    body = node.only_child()
    name = ctx.attrs.text(node, "name")
    if body.tag == "GlobalAction":
        return Action(name, parse_global_action(body, ctx))
    if body.tag != "PrivateAction":
        raise unsupported(body)
    return Action(name, parse_private_action(body, ctx))


def parse_event(node: Node, ctx: Context) -> Event:
    a = ctx.attrs
    actions = tuple(parse_action(x, ctx) for x in node.all("Action"))
    if not actions:
        raise node.error("needs at least one Action")
    return Event(
        name=a.text(node, "name"),
        priority=a.choice(node, "priority", PRIORITIES),  # type: ignore[arg-type]
        maximum_execution_count=a.integer_or(node, "maximumExecutionCount", 1),
        actions=actions,
        start_trigger=parse_trigger(node.child("StartTrigger"), ctx),
    )


def parse_maneuver(node: Node, ctx: Context) -> Maneuver:
    """A Maneuver element, or a CatalogReference to one."""
    if node.tag == "CatalogReference":
        entry = ctx.catalogs.resolve(node, ctx.attrs, ("Maneuver",))
        return parse_maneuver(entry.node, ctx.in_scope(entry.scope, entry.node))
    ctx = ctx.with_declarations(node)
    return Maneuver(
        name=ctx.attrs.text(node, "name"),
        events=tuple(parse_event(e, ctx) for e in node.all("Event")),
    )


def parse_maneuver_group(node: Node, ctx: Context) -> ManeuverGroup:
    a = ctx.attrs
    actors = node.need("Actors")
    for child in actors.children:
        if child.tag != "EntityRef":
            raise unsupported(child)
    return ManeuverGroup(
        name=a.text(node, "name"),
        maximum_execution_count=a.integer(node, "maximumExecutionCount"),
        actors=Actors(
            entities=tuple(ctx.entity_ref(e) for e in actors.all("EntityRef")),
            select_triggering_entities=a.boolean(actors, "selectTriggeringEntities"),
        ),
        maneuvers=tuple(
            parse_maneuver(m, ctx)
            for m in node.children
            if m.tag in ("Maneuver", "CatalogReference")
        ),
    )


def parse_act(node: Node, ctx: Context) -> Act:
    return Act(
        name=ctx.attrs.text(node, "name"),
        maneuver_groups=tuple(parse_maneuver_group(g, ctx) for g in node.all("ManeuverGroup")),
        start_trigger=parse_trigger(node.child("StartTrigger"), ctx),
        stop_trigger=parse_trigger(node.child("StopTrigger"), ctx),
    )


def parse_story(node: Node, ctx: Context) -> Story:
    ctx = ctx.with_declarations(node)  # 1.0 allows ParameterDeclarations in a Story
    return Story(ctx.attrs.text(node, "name"), tuple(parse_act(x, ctx) for x in node.all("Act")))


_ELEMENT_TYPES = {
    "Story": "story",
    "Act": "act",
    "ManeuverGroup": "maneuverGroup",
    "Maneuver": "maneuver",
    "Event": "event",
    "Action": "action",
}


def element_names(node: Node, ctx: Context) -> dict[str, frozenset[str]] | None:
    """The names of the storyboard's elements by StoryboardElementType, or None when a
    maneuver comes from a catalog (its names are not checked then)."""
    names: dict[str, set[str]] = {t: set() for t in _ELEMENT_TYPES.values()}
    stack = [node]
    while stack:
        current = stack.pop()
        if current.tag == "ManeuverGroup" and current.child("CatalogReference") is not None:
            return None
        kind = _ELEMENT_TYPES.get(current.tag)
        if kind is not None and current.parent is not None and current.parent.tag != "Init":
            names[kind].add(ctx.attrs.text(current, "name"))
        stack.extend(current.children)
    return {kind: frozenset(found) for kind, found in names.items()}


def parse_storyboard(node: Node, ctx: Context) -> Storyboard:
    ctx = replace(ctx, element_names=element_names(node, ctx))
    return Storyboard(
        init=parse_init(node.child("Init"), ctx),
        init_global=parse_init_global(node.child("Init"), ctx),
        stories=tuple(parse_story(s, ctx) for s in node.all("Story")),
        stop_trigger=parse_trigger(node.child("StopTrigger"), ctx),
    )
