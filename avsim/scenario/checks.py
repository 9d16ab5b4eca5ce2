"""Checks that span several keys of a validated scenario file, which the models alone cannot
make: a lane exists at its station, stations lie on the route (so does a criteria setting
declared a station, `reach_s`), `after` names an earlier action, arcs are wider than the
road, actor ids are unique, speeds fit the car, a speed action's acceleration has the sign
its change of speed needs, in a town every car starts on its route, and no two bodies
overlap where they start (`check_spawn`).

Each check raises the first problem it finds as a `LocatedError` at its key; the order of
the checks is the order in which a file's problems are reported. Stations are metres along
the route (the ego's, or in a town each car's own) from its start.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypeVar

from avsim.criteria.registry import keyed
from avsim.scenario.errors import LocatedError, fmt
from avsim.scenario.model import ActorModel, RoadModel, ScenarioModel, TriggerModel
from vehicle_urdf import CarDimensions
from world import spec
from world.actors.bodies import body_size
from world.map.rectangles import Corners, overlap, rectangle
from world.map.road import build_road_map

DEFAULT_SPEED_UP = 2.0  # [m/s^2] a speed action's accel when it speeds up
DEFAULT_SLOW_DOWN = -3.0  # [m/s^2] a speed action's accel when it slows down

_T = TypeVar("_T")


def check_road(model: ScenarioModel, road: RoadModel,
               segments: Sequence[spec.SegmentSpec]) -> None:
    """Every cross-key check of a file on a route road; `segments` are the road's, converted."""
    _check_arcs(road)
    _check_exits(road)
    _check_ego(model, segments)
    _check_actors(model, segments)
    _check_rest(model, road, segments)


def check_town(model: ScenarioModel, ego_road: spec.RoadSpec,
               roads: Sequence[spec.RoadSpec]) -> None:
    """Every cross-key check of a file in a town, once each car's route is compiled:
    `ego_road` is the ego's, `roads` the actors' (in the file's order)."""
    _check_town_car("ego", model.ego.lane, model.ego.s, ego_road)
    for index, (actor, road) in enumerate(zip(model.actors, roads, strict=True)):
        _check_town_car(f"actors.{index}", actor.lane, actor.s, road)
        speed_accels(f"actors.{index}", actor)
    _check_town_ids(model)
    length = route_length(ego_road.segments)
    for index, event in enumerate(model.events):
        _check_trigger(f"events.{index}.trigger", event.trigger, index, length, "event")
    _check_criteria_stations(model, length)
    for key in ("speed_kph", "set_speed_kph"):
        if getattr(model.ego, key) > model.ego.max_speed_kph:
            raise LocatedError(f"ego.{key}", f"must be <= max_speed_kph "
                               f"({fmt(model.ego.max_speed_kph)}), got "
                               f"{fmt(getattr(model.ego, key))}")


def check_spawn(world: spec.WorldSpec) -> None:
    """No two bodies overlap where they start. On a road: the ego and each actor,
    each a box of its length and width along the lane it starts in (at its offset), the
    ego's `vehicle_urdf.CarDimensions`'; the first overlap found is refused at the later
    body's key: ``actors.2: overlaps the ego at s = 11 m``. Pedestrians and obstacles count
    like vehicles. Along the route the boxes are compared station by station (an arc's
    radius is far larger than a car)."""
    if world.town is not None:
        _check_town_spawn(world)
        return
    road = build_road_map(world.road)
    car = CarDimensions()
    boxes = [("the ego", world.ego.s,
              road.lane(world.ego.lane).offset_at(world.ego.s) + world.ego.offset,
              car.body_length, car.body_width)]
    for index, actor in enumerate(world.actors):
        if actor.road is not None:  # in a town: on its own route
            continue
        size = body_size(actor)
        lateral = road.lane(actor.lane).offset_at(actor.s) + actor.offset
        box = (f"actors.{index} ({actor.id})", actor.s, lateral, size.length, size.width)
        for name, s, offset, length, width in boxes:
            if (abs(actor.s - s) < (size.length + length) / 2
                    and abs(lateral - offset) < (size.width + width) / 2):
                raise LocatedError(f"actors.{index}",
                                   f"overlaps {name} at s = {fmt(actor.s)} m")
        boxes.append(box)


def _check_town_spawn(world: spec.WorldSpec) -> None:
    """`check_spawn` in a town: each car starts on its own route, so the bodies are placed in
    the world (the centre at its station and offset on its route, the length along the
    route's heading there) and compared as rectangles (`world.map.rectangles`)."""
    car = CarDimensions()
    placed = [("the ego", _footprint(world.road, world.ego.lane, world.ego.s, 0.0,
                                     car.body_length, car.body_width))]
    for index, actor in enumerate(world.actors):
        size = body_size(actor)
        here = _footprint(actor.road or world.road, actor.lane, actor.s, actor.offset,
                          size.length, size.width)
        for name, other in placed:
            if overlap(here, other):
                raise LocatedError(f"actors.{index}",
                                   f"overlaps {name} at s = {fmt(actor.s)} m of its route")
        placed.append((f"actors.{index} ({actor.id})", here))


def _footprint(road: spec.RoadSpec, lane_index: int, s: float, offset: float, length: float,
               width: float) -> Corners:
    """The ground rectangle of a body centred at station s and `offset` on a lane of `road`."""
    lane = build_road_map(road).lane(lane_index)
    x, y = (float(v) for v in lane.position(s, offset))
    return rectangle(x, y, float(lane.heading_at(s)), length, width)


def route_length(segments: Sequence[spec.SegmentSpec]) -> float:
    """[m] the route's length: its segments' lengths added up."""
    return sum(segment.length for segment in segments)


def _segment_at(segments: Sequence[spec.SegmentSpec], s: float) -> spec.SegmentSpec:
    """The segment at station s (a joint belongs to the later segment; the end to the last)."""
    start = 0.0
    for segment in segments:
        if s < start + segment.length:
            return segment
        start += segment.length
    return segments[-1]


def _check_station(key: str, s: float, length: float) -> None:
    """Station s [m] is not beyond the route's end, `length` [m]."""
    if s > length:
        raise LocatedError(
            key, f"station {fmt(s)} m is beyond the end of the route ({fmt(length)} m)"
        )


def _check_lane(
    key: str, lane: int, s: float, segments: Sequence[spec.SegmentSpec], oncoming: bool
) -> None:
    """Lane `lane` exists at station s (oncoming lanes -1, -2, ... only if `oncoming`)."""
    segment = _segment_at(segments, s)
    lowest = -segment.oncoming_lanes if oncoming else 0
    if lowest <= lane < segment.lanes:
        return
    there = f"the road has {segment.lanes} lane{'s' if segment.lanes != 1 else ''} there"
    if oncoming and segment.oncoming_lanes:
        there += f" and {segment.oncoming_lanes} oncoming (-1 to -{segment.oncoming_lanes})"
    raise LocatedError(key, f"lane {lane} does not exist at s = {fmt(s)} m ({there})")


def _check_arcs(road: RoadModel) -> None:
    """Every arc's radius exceeds the road's whole paved width (conservative: the inner
    paved edge stays clear of the arc's centre whichever way it turns)."""
    for index, segment in enumerate(road.segments):
        if segment.arc is None:
            continue
        lanes = (given_or(segment.lanes, road.lanes)
                 + given_or(segment.oncoming_lanes, road.oncoming_lanes))
        width = lanes * road.lane_width + given_or(segment.shoulder, road.shoulder)
        if not segment.arc.radius > width:
            raise LocatedError(
                f"road.segments.{index}.arc.radius",
                f"must be larger than the road's paved width there, {fmt(width)} m "
                f"((lanes + oncoming_lanes) x lane_width + shoulder), "
                f"got {fmt(segment.arc.radius)}",
            )


def _check_exits(road: RoadModel) -> None:
    """An exit leaves the road of the segment before it: not on the first segment."""
    if road.segments and road.segments[0].exit is not None:
        raise LocatedError("road.segments.0.exit",
                            "the first segment has no road before it to leave")


def _check_ego(model: ScenarioModel, segments: Sequence[spec.SegmentSpec]) -> None:
    """On a road: the ego has a station on the route and a lane there, no town keys, and
    its speeds within its `max_speed_kph`."""
    ego = model.ego
    for town_key in ("start", "route"):
        if getattr(ego, town_key) is not None:
            raise LocatedError(f"ego.{town_key}", "only for a town map (on a road use lane and s)")
    if ego.s is None:
        raise LocatedError("ego.s", "required key missing (the ego's station on the road)")
    _check_station("ego.s", ego.s, route_length(segments))
    _check_lane("ego.lane", given_or(ego.lane, 0), ego.s, segments, oncoming=False)
    for key in ("speed_kph", "set_speed_kph"):
        value = getattr(ego, key)
        if value > ego.max_speed_kph:
            raise LocatedError(
                f"ego.{key}",
                f"must be <= max_speed_kph ({fmt(ego.max_speed_kph)}), got {fmt(value)}",
            )


def _check_actors(model: ScenarioModel, segments: Sequence[spec.SegmentSpec]) -> None:
    """On a road: unique actor ids, and each actor's checks in the file's order."""
    first_seen: dict[str, int] = {}
    for index, actor in enumerate(model.actors):
        key = f"actors.{index}"
        if actor.id in first_seen:
            raise LocatedError(
                f"{key}.id", f"duplicate id {actor.id!r} (also actors.{first_seen[actor.id]})"
            )
        first_seen[actor.id] = index
        _check_actor(key, actor, segments)


def _check_actor(key: str, actor: ActorModel, segments: Sequence[spec.SegmentSpec]) -> None:
    """One actor on a road: no town keys, a station on the route and a lane there (oncoming
    allowed), an obstacle stands still, its triggers and lane changes are sound, its speed
    actions' accelerations have the right sign."""
    for town_key in ("start", "route"):
        if getattr(actor, town_key) is not None:
            raise LocatedError(
                f"{key}.{town_key}", "only for a town map (on a road use lane and s)"
            )
    if actor.s is None:
        raise LocatedError(f"{key}.s", "required key missing (the actor's station on the road)")
    length = route_length(segments)
    _check_station(f"{key}.s", actor.s, length)
    _check_lane(f"{key}.lane", given_or(actor.lane, 0), actor.s, segments, oncoming=True)
    if actor.type == "obstacle" and actor.speed_kph != 0:
        raise LocatedError(
            f"{key}.speed_kph", f"an obstacle does not move: must be 0, got {fmt(actor.speed_kph)}"
        )
    if actor.type == "obstacle" and actor.actions:
        raise LocatedError(f"{key}.actions", "an obstacle does not move: it takes no actions")
    for number, action in enumerate(actor.actions):
        action_key = f"{key}.actions.{number}"
        _check_trigger(f"{action_key}.trigger", action.trigger, number, length, "action")
        if action.lane_change is not None:
            _check_lane(
                f"{action_key}.lane_change.to_lane",
                action.lane_change.to_lane,
                actor.s,
                segments,
                oncoming=True,
            )
    speed_accels(key, actor)


def _check_trigger(key: str, trigger: TriggerModel, index: int, length: float, what: str) -> None:
    """`after` names an earlier item of the same list; `ego_s` lies on the route."""
    if trigger.after is not None and trigger.after >= index:
        earlier = f"0..{index - 1}" if index > 0 else f"none: this is the first {what}"
        raise LocatedError(
            f"{key}.after", f"must refer to an earlier {what} ({earlier}), got {trigger.after}"
        )
    if trigger.ego_s is not None:
        _check_station(f"{key}.ego_s", trigger.ego_s, length)


def _check_rest(
    model: ScenarioModel, road: RoadModel, segments: Sequence[spec.SegmentSpec]
) -> None:
    """Features, events and criteria that refer to stations or list indices."""
    length = route_length(segments)
    for index, feature in enumerate(road.features):
        _check_station(f"road.features.{index}.s", feature.s, length)
    for index, event in enumerate(model.events):
        _check_trigger(f"events.{index}.trigger", event.trigger, index, length, "event")
        if event.trigger.gap is not None:
            raise LocatedError(
                f"events.{index}.trigger.gap", "only for actors (the gap to the ego)"
            )
    _check_criteria_stations(model, length)


def _check_criteria_stations(model: ScenarioModel, length: float) -> None:
    """A criteria setting that is a station (`reach_s`) lies on the route."""
    for declaration in keyed():
        value = getattr(model.criteria, str(declaration.key))
        if declaration.on_route and value is not None:
            _check_station(f"criteria.{declaration.key}", value, length)


def speed_accels(key: str, actor: ActorModel) -> dict[int, float]:
    """[m/s^2] the signed acceleration of each speed action, by action index.

    The speed before an action is taken as the target of the speed / stop action before it
    in the list (the actor's initial speed for the first): it picks the default
    (`DEFAULT_SPEED_UP` when speeding up, `DEFAULT_SLOW_DOWN` when slowing) and a given accel
    must have the matching sign."""
    accels: dict[int, float] = {}
    speed_kph = actor.speed_kph
    for index, action in enumerate(actor.actions):
        if action.speed is not None:
            target = action.speed.kph
            accel = action.speed.accel
            if accel is None:
                accel = DEFAULT_SPEED_UP if target >= speed_kph else DEFAULT_SLOW_DOWN
            elif (target - speed_kph) * accel < 0:
                sign = "> 0" if target > speed_kph else "< 0"
                raise LocatedError(
                    f"{key}.actions.{index}.speed.accel",
                    f"must be {sign} to go from {fmt(speed_kph)} to {fmt(target)} km/h "
                    f"(signed acceleration), got {fmt(accel)}",
                )
            accels[index] = accel
            speed_kph = target
        elif action.stop is not None:
            speed_kph = 0.0
    return accels


def given_or(value: _T | None, default: _T) -> _T:
    """`value`, or `default` when it is None."""
    return default if value is None else value


def _check_town_car(key: str, lane: int | None, s: float | None, road: spec.RoadSpec) -> None:
    """In a town a car starts in lane 0 of its route, `s` metres past its start junction."""
    if lane not in (None, 0):
        raise LocatedError(f"{key}.lane", "in a town a car starts in lane 0 of its route")
    if s is not None:
        _check_station(f"{key}.s", s, route_length(road.segments))


def _check_town_ids(model: ScenarioModel) -> None:
    """In a town: unique actor ids."""
    first_seen: dict[str, int] = {}
    for index, actor in enumerate(model.actors):
        if actor.id in first_seen:
            raise LocatedError(f"actors.{index}.id", f"duplicate id {actor.id!r} "
                               f"(also actors.{first_seen[actor.id]})")
        first_seen[actor.id] = index

