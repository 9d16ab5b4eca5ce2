"""Judging one condition at one step (`holds`), and a condition with its triggering
entities (`judge`). Behaves as esmini's `OSCCondition` where not said otherwise.

Rules: `rules.compare` (floats equal within 1e-6 absolute, ints and strings exactly).
Entity conditions are judged per triggering entity; rule "any": true when it holds for one
of them, "all": for every one (the entities it holds for are the ones
`selectTriggeringEntities` adds). Distances (`geometry`) are along the ego's route:
coordinate systems "entity", "lane", "road" and "trajectory" are all taken along the route
(the route is the lane kept; an entity's own axes are not used). Relative and position
distances compare their magnitude. An entity missing from the snapshot: false. An entity
out of the world (deleted, or not yet added: `Snapshot.inactive`) is skipped as esmini
skips an inactive one: as a triggering entity it neither holds nor counts for rule "all"
(which holds when every entity in the world does, and one at least is); as a condition's
reference entity, or as another entity a collision or clearance looks for, it is absent
(false, nothing to meet). Notes
particular to a kind are on its judge below; the conditions on variables, time of day,
acceleration, angles and clearance are judged in `state_conditions`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

from avsim.run.storyboard import geometry as g
from avsim.run.storyboard import state_conditions as sc
from avsim.run.storyboard.elements import ElementState, TransitionKind, TransitionRecord
from avsim.run.storyboard.rules import compare, parameter_holds
from avsim.run.storyboard.snapshot import EntityState, Snapshot
from avsim.run.storyboard.state import StoryState
from avsim.scenario.openscenario.conditions import (
    AccelerationCondition,
    AngleCondition,
    CollisionCondition,
    Condition,
    ConditionKind,
    DistanceCondition,
    EndOfRoadCondition,
    OffroadCondition,
    ParameterCondition,
    ReachPositionCondition,
    RelativeAngleCondition,
    RelativeClearanceCondition,
    RelativeDistanceCondition,
    RelativeDistanceType,
    RelativeSpeedCondition,
    SimulationTimeCondition,
    SpeedCondition,
    StandStillCondition,
    StoryboardElementStateCondition,
    TimeHeadwayCondition,
    TimeOfDayCondition,
    TimeToCollisionCondition,
    TraveledDistanceCondition,
    VariableCondition,
)
from avsim.scenario.openscenario.parameters import ParamValue
from avsim.scenario.openscenario.positions import Position
from world.map.rectangles import rectangle

STANDING = 0.01  # [m/s] below this an entity stands still (as the snapshot's standing_for)
Resolved = tuple[float, float, float, float]  # x, y [m] map frame; s, offset [m] route
Resolver = Callable[[Position, Snapshot], Resolved]


def no_resolver(position: Position, snap: Snapshot) -> Resolved:
    raise ValueError(f"no position resolver given for {type(position).__name__}")


@dataclass(frozen=True, slots=True)
class ConditionContext:
    """What conditions read besides the snapshot."""

    parameters: Mapping[str, ParamValue]
    states: Mapping[tuple[str, str], ElementState]  # (element type, name) -> state now
    log: Sequence[TransitionRecord] = ()  # every transition so far, in order
    since: int = 0  # log[since:] happened since the condition's previous evaluation
    resolve: Resolver = no_resolver  # a position -> (x, y, s, offset)
    state: StoryState = field(default_factory=StoryState)  # variables, environment (live)
    lanes: sc.Lanes = sc.no_lanes  # a station -> the route's lane counts there (clearance)


_STATES = {s.value: s for s in ElementState}
_TRANSITIONS = {k.value: k for k in TransitionKind}


def _element_state(c: StoryboardElementStateCondition, ctx: ConditionContext) -> bool:
    """A state: the element is in it now. A transition: it happened since the condition's
    previous evaluation (`ctx.since`); esmini keeps the same per-condition list. A 1.2
    qualified reference (`Story::Act`) is looked up by its last name."""
    name = c.element_ref.split("::")[-1]
    if c.state in _STATES:
        return ctx.states.get((c.element_type, name)) is _STATES[c.state]
    kind = _TRANSITIONS[c.state]
    return any(r.transition is kind and r.name == name and r.element_type == c.element_type
               for r in ctx.log[ctx.since:])


def _by_value(kind: ConditionKind, snap: Snapshot, ctx: ConditionContext) -> bool:
    if isinstance(kind, SimulationTimeCondition):
        return compare(snap.time, kind.rule, kind.value)
    if isinstance(kind, ParameterCondition):
        return parameter_holds(kind, ctx.parameters)
    if isinstance(kind, StoryboardElementStateCondition):
        return _element_state(kind, ctx)
    if isinstance(kind, VariableCondition):
        return sc.variable(kind, ctx)
    if isinstance(kind, TimeOfDayCondition):
        return sc.time_of_day(kind, snap, ctx)
    raise TypeError(f"{type(kind).__name__} needs a triggering entity")


def _relative(a: EntityState, b: EntityState, dtype: RelativeDistanceType,
              freespace: bool) -> float:
    """[m] the magnitude of the distance of this type between a and b."""
    if dtype == "longitudinal":
        return abs(g.longitudinal(a, b, freespace))
    if dtype == "lateral":
        return abs(g.lateral(a, b, freespace))
    return g.cartesian(a, b, freespace)


def _relative_distance(c: RelativeDistanceCondition, e: EntityState, snap: Snapshot,
                       _ctx: ConditionContext) -> bool:
    return compare(_relative(e, snap.entities[c.entity], c.distance_type, c.freespace),
                   c.rule, c.value)


def _to_position(e: EntityState, p: Resolved, dtype: RelativeDistanceType,
                 freespace: bool) -> float:
    """[m] from the entity (its reference point, or freespace its box) to a point."""
    x, y, s, offset = p
    if dtype == "longitudinal":
        d = abs(s - g.centre_station(e)) - e.length / 2.0 if freespace else abs(s - e.s)
        return max(d, 0.0)
    if dtype == "lateral":
        c = g.centre_offset(e)
        d = abs(offset - c) - e.width / 2.0 if freespace else abs(offset - e.offset)
        return max(d, 0.0)
    if freespace:
        point = rectangle(x, y, 0.0, 0.0, 0.0)
        return g.rectangle_distance(g.corners(e), point)
    return math.hypot(x - e.x, y - e.y)


def _distance(c: DistanceCondition, e: EntityState, snap: Snapshot,
              ctx: ConditionContext) -> bool:
    p = ctx.resolve(c.position, snap)
    return compare(_to_position(e, p, c.distance_type, c.freespace), c.rule, c.value)


def _headway(c: TimeHeadwayCondition, e: EntityState, snap: Snapshot,
             _ctx: ConditionContext) -> bool:
    """Distance to the entity (longitudinal along the route, or cartesian) over the
    triggering entity's speed; false when it stands or drives backwards, or the entity is
    behind it (esmini: headway undefined)."""
    other = snap.entities[c.entity]
    ahead = g.longitudinal(e, other, c.freespace)
    if e.speed < 1e-9 or ahead < 0.0:
        return False
    d = ahead if c.distance_type == "longitudinal" else _relative(e, other, c.distance_type,
                                                                   c.freespace)
    return compare(d / e.speed, c.rule, c.value)


def _along(e: EntityState) -> float:
    """[m/s] the entity's speed along the route."""
    return e.speed * math.cos(e.heading - e.route_heading)


def _ttc(c: TimeToCollisionCondition, e: EntityState, snap: Snapshot,
         ctx: ConditionContext) -> bool:
    """Distance (longitudinal gap along the route, or cartesian) over the closing speed
    along the route; 0 s when touching; false when not closing."""
    if c.entity is not None:
        other = snap.entities[c.entity]
        ahead = g.longitudinal(e, other, c.freespace)
        closing = (_along(e) - _along(other)) * math.copysign(1.0, ahead)
        d = abs(ahead) if c.distance_type == "longitudinal" else _relative(
            e, other, c.distance_type, c.freespace)
    else:
        assert c.position is not None
        p = ctx.resolve(c.position, snap)
        ahead = p[2] - e.s
        closing = _along(e) * math.copysign(1.0, ahead)
        d = _to_position(e, p, c.distance_type, c.freespace)
    if d <= 0.0:
        return compare(0.0, c.rule, c.value)
    return closing > 0.0 and compare(d / closing, c.rule, c.value)


def _reach(c: ReachPositionCondition, e: EntityState, snap: Snapshot,
           ctx: ConditionContext) -> bool:
    x, y, _s, _o = ctx.resolve(c.position, snap)
    return math.hypot(x - e.x, y - e.y) <= c.tolerance


def _traveled(c: TraveledDistanceCondition, e: EntityState, _snap: Snapshot,
              _ctx: ConditionContext) -> bool:
    return e.odometer >= c.value


def _speed(c: SpeedCondition, e: EntityState, _snap: Snapshot, _ctx: ConditionContext) -> bool:
    return compare(e.speed, c.rule, c.value)


def _relative_speed(c: RelativeSpeedCondition, e: EntityState, snap: Snapshot,
                    _ctx: ConditionContext) -> bool:
    return compare(e.speed - snap.entities[c.entity].speed, c.rule, c.value)


def _standstill(c: StandStillCondition, e: EntityState, _snap: Snapshot,
                _ctx: ConditionContext) -> bool:
    return abs(e.speed) < STANDING and e.standing_for >= c.duration


def _end_of_road(c: EndOfRoadCondition, e: EntityState, _snap: Snapshot,
                 _ctx: ConditionContext) -> bool:
    """Beyond the route's ends for `duration` (the snapshot's timer is 0 both on the road
    and at the first step beyond it, so duration 0 holds from the second step beyond)."""
    return e.end_of_road_for > 0.0 and e.end_of_road_for >= c.duration


def _offroad(c: OffroadCondition, e: EntityState, _snap: Snapshot,
             _ctx: ConditionContext) -> bool:
    """Off the paved road for `duration` (duration 0: as `_end_of_road`)."""
    return e.off_road_for > 0.0 and e.off_road_for >= c.duration


def _collision(c: CollisionCondition, e: EntityState, snap: Snapshot,
               _ctx: ConditionContext) -> bool:
    """The entity's bounding box overlaps (or touches) the named entity's, or that of any
    other entity of the category `by_type`: the boxes in the map's plane (the standard's
    collision between bounding boxes, as esmini judges it), not the physics bodies' contacts."""
    if c.entity is not None:
        others = [snap.entities[c.entity]] if c.entity in snap.entities else []
    else:
        others = [o for n, o in snap.entities.items()
                  if n != e.name and snap.categories.get(n) == c.by_type]
    return any(g.boxes_meet(e, o) for o in others if o.name != e.name)


EntityJudge = Callable[[ConditionKind, EntityState, Snapshot, ConditionContext], bool]
_BY_ENTITY: dict[type, EntityJudge] = {
    RelativeDistanceCondition: _relative_distance,  # type: ignore[dict-item]
    DistanceCondition: _distance,  # type: ignore[dict-item]
    TimeHeadwayCondition: _headway,  # type: ignore[dict-item]
    TimeToCollisionCondition: _ttc,  # type: ignore[dict-item]
    ReachPositionCondition: _reach,  # type: ignore[dict-item]
    TraveledDistanceCondition: _traveled,  # type: ignore[dict-item]
    SpeedCondition: _speed,  # type: ignore[dict-item]
    RelativeSpeedCondition: _relative_speed,  # type: ignore[dict-item]
    StandStillCondition: _standstill,  # type: ignore[dict-item]
    EndOfRoadCondition: _end_of_road,  # type: ignore[dict-item]
    OffroadCondition: _offroad,  # type: ignore[dict-item]
    CollisionCondition: _collision,  # type: ignore[dict-item]
    AccelerationCondition: sc.acceleration,  # type: ignore[dict-item]
    AngleCondition: sc.angle,  # type: ignore[dict-item]
    RelativeAngleCondition: sc.relative_angle,  # type: ignore[dict-item]
    RelativeClearanceCondition: sc.clearance,  # type: ignore[dict-item]
}


def holds(kind: ConditionKind, triggering: str | None, snap: Snapshot,
          ctx: ConditionContext) -> bool:
    """Whether the condition `kind` holds now, for the triggering entity `triggering` (None
    for a by-value condition). An entity missing from the snapshot: false."""
    judge = _BY_ENTITY.get(type(kind))
    if judge is None:
        return _by_value(kind, snap, ctx)
    if triggering is None:
        raise TypeError(f"{type(kind).__name__} needs a triggering entity")
    if triggering not in snap.entities or _missing_reference(kind, snap):
        return False
    return judge(kind, snap.entities[triggering], snap, ctx)


def _missing_reference(kind: ConditionKind, snap: Snapshot) -> bool:
    other = getattr(kind, "entity", None)
    return isinstance(other, str) and not isinstance(kind, CollisionCondition) \
        and other not in snap.entities


def judge(condition: Condition, snap: Snapshot,
          ctx: ConditionContext) -> tuple[bool, tuple[str, ...]]:
    """Whether `condition` (its edge and delay aside) holds now, and the triggering entities
    it holds for (all of them for rule "all" when it holds; () for a by-value one)."""
    te = condition.triggering_entities
    if te is None:
        return holds(condition.kind, None, snap, ctx), ()
    present = tuple(n for n in te.entities if n not in snap.inactive)
    snap = snap.active()
    hits = tuple(n for n in present if holds(condition.kind, n, snap, ctx))
    ok = bool(hits) if te.rule == "any" else len(hits) == len(present) > 0
    return ok, hits
