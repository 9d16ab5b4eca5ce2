"""Hand-made snapshots and storyboard pieces for the storyboard tests."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

from avsim.run.storyboard.conditions import ConditionContext
from avsim.run.storyboard.elements import ElementState
from avsim.run.storyboard.snapshot import EntityState, Snapshot
from avsim.scenario.openscenario.actions import (
    AbsoluteTargetSpeed,
    ActivateControllerAction,
    SpeedAction,
    TransitionDynamics,
)
from avsim.scenario.openscenario.conditions import (
    Condition,
    ConditionGroup,
    ConditionKind,
    Edge,
    SimulationTimeCondition,
    Trigger,
    TriggeringEntities,
)
from avsim.scenario.openscenario.storyboard import (
    Act,
    Action,
    Actors,
    Event,
    Maneuver,
    ManeuverGroup,
    Priority,
    Story,
    Storyboard,
)


def entity(name: str = "Ego", **changes: float | int | None) -> EntityState:
    """A car on the route: reference point at (s, offset) = (x, y), heading along it."""
    base = EntityState(name=name, x=0.0, y=0.0, heading=0.0, speed=0.0, s=0.0, offset=0.0,
                       lane=0, route_heading=0.0, length=4.0, width=2.0, centre_ahead=1.5,
                       odometer=0.0, standing_for=0.0, off_road_for=0.0, end_of_road_for=0.0)
    e = dataclasses.replace(base, **changes)  # type: ignore[arg-type]
    if "x" in changes and "s" not in changes:
        e = dataclasses.replace(e, s=e.x)
    if "y" in changes and "offset" not in changes:
        e = dataclasses.replace(e, offset=e.y)
    return e


def snapshot(*entities: EntityState, t: float = 0.0,
             categories: Mapping[str, str] | None = None) -> Snapshot:
    cats = categories or {e.name: "vehicle" for e in entities}
    return Snapshot(t, {e.name: e for e in entities}, cats)


def context(parameters: Mapping[str, int | float | bool | str] | None = None,
            states: Mapping[tuple[str, str], ElementState] | None = None) -> ConditionContext:
    return ConditionContext(parameters or {}, states or {})


def condition(kind: ConditionKind, edge: Edge = "none", delay: float = 0.0,
              entities: tuple[str, ...] | None = None, rule: str = "any",
              name: str = "C") -> Condition:
    te = None if entities is None else TriggeringEntities(rule, entities)  # type: ignore[arg-type]
    return Condition(name, delay, edge, te, kind)


def trigger(*groups: tuple[Condition, ...]) -> Trigger:
    return Trigger(tuple(ConditionGroup(g) for g in groups))


def at_time(t: float, edge: Edge = "none", delay: float = 0.0) -> Trigger:
    """Fires when the simulation time is >= t."""
    return trigger((condition(SimulationTimeCondition(t, "greaterOrEqual"), edge, delay),))


SPEED = SpeedAction(TransitionDynamics("linear", "rate", 2.0, None), AbsoluteTargetSpeed(10.0))
ACTIVATE = ActivateControllerAction(True, True, None, None)


def event(name: str, start: Trigger | None, priority: Priority = "overwrite", count: int = 1,
          actions: tuple[str, ...] = ("A",), instant: bool = False) -> Event:
    act = ACTIVATE if instant else SPEED
    return Event(name, priority, count, tuple(Action(f"{name}{a}", act) for a in actions), start)


def storyboard(*events: Event, act_start: Trigger | None = None, act_stop: Trigger | None = None,
               stop: Trigger | None = None, group_count: int = 1,
               actors: tuple[str, ...] = ("Ego",), select: bool = False) -> Storyboard:
    """One story, one act, one group, one maneuver holding `events`."""
    group = ManeuverGroup("G", group_count, Actors(actors, select), (Maneuver("M", events),))
    return Storyboard((), (Story("S", (Act("Act", (group,), act_start, act_stop),)),), stop)
