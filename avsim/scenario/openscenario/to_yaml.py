"""`avsim convert FILE.xosc`: an OpenSCENARIO file as the equivalent `avsim/1` YAML where
it fits that format, and what does not fit.

The YAML is built from what the file loads into (`convert.load_xosc`): the route's pieces
(straight runs merged; an OpenDRIVE road's clothoids and cubics as the arcs of its arc
spline, within 1 mm), the car under test's start and set speed, each actor's start and
model (a catalogue model by class and nearest length where the file's box is none of
them), the sidecar's criteria. Each story event that acts on one actor becomes one of its
`actions` when its trigger and action have a YAML form:

- trigger: `SimulationTime` >= t (+ delay) -> `time`; a longitudinal free-space
  `RelativeDistance` to the car under test below d -> `gap`; an earlier action of the
  same actor ended (`StoryboardElementState` end / complete, + delay) -> `after`;
- action: a `SpeedAction` to an absolute speed, or one relative to the car under test's
  Init speed (not continuous), step or linear -> `speed` (a rate as its `accel`, a time as
  the change over it); a `LaneChangeAction` to a route lane -> `lane_change` (its rate as
  `lateral_speed`; the YAML's profile is trapezoidal, a shape is noted).

The StopTrigger becomes `duration` when it is one `SimulationTime` condition. Everything
else is listed as not fitting (the YAML is then an approximation, and says so).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from avsim.scenario.bounds import MAX_LANE_WIDTH, MAX_RADIUS
from avsim.scenario.openscenario.convert import load_xosc
from avsim.scenario.openscenario.environment import EnvironmentAction
from avsim.scenario.openscenario.model import (
    AbsoluteTargetLane,
    AbsoluteTargetSpeed,
    ActivateControllerAction,
    AssignControllerAction,
    Condition,
    Event,
    LaneChangeAction,
    RelativeDistanceCondition,
    RelativeTargetLane,
    RelativeTargetSpeed,
    SimulationTimeCondition,
    SpeedAction,
    StoryboardElementStateCondition,
    Trigger,
)
from avsim.scenario.openscenario.variables import VariableAction
from avsim.scenario.scenario import Scenario
from world.actors.catalogue import CATALOGUE, VehicleModel
from world.frames import MPS_PER_KPH
from world.spec import ActorSpec, RoadSpec

RADIUS_DIGITS = 6  # rounding of the YAML's numbers (mm and finer)
ENDED = frozenset({"endTransition", "completeState"})


@dataclass
class Conversion:
    """The YAML document and what did not fit into it."""

    document: dict[str, Any]
    misfits: list[str] = field(default_factory=list)
    converted: list[str] = field(default_factory=list)  # the actions written, by name


def convert_xosc(path: Path, criteria_file: Path | None = None,
                 search_paths: Sequence[Path] = (),
                 overrides: Mapping[str, object] | None = None) -> Conversion:
    """The `avsim/1` YAML of an OpenSCENARIO file (module doc) with `overrides` (its
    `parameters.NAME`, as `load_xosc` takes them), its references found in its folder tree
    or `search_paths`; `ScenarioError` if it does not load."""
    return convert_scenario(load_xosc(path, overrides, criteria_file, search_paths), path)


def convert_scenario(scenario: Scenario, path: Path) -> Conversion:
    """The `avsim/1` YAML of the scenario `load_xosc` made of the file at `path`."""
    out = Conversion({})
    story = scenario.story
    assert story is not None
    ego = scenario.world.ego
    out.document = {
        "format": "avsim/1", "name": scenario.name,
        "description": scenario.description or f"converted from {path.name}",
        "duration": _duration(scenario, out),
        "road": _road(scenario.world.road, out),
        "ego": {"lane": ego.lane, "s": _r(ego.s), "speed_kph": _kph(ego.speed),
                "set_speed_kph": _kph(scenario.driver.set_speed),
                "max_speed_kph": _kph(ego.max_speed)},
    }
    if ego.offset != 0.0:
        out.misfits.append(f"the ego starts {ego.offset:+.2f} m off its lane's centre: the "
                           "YAML ego starts on it")
    _scenery(scenario, out)
    actors = [_actor(a, out) for a in scenario.world.actors]
    names = {name: i for name, i in story.actors}
    _story(scenario, names, actors, out)
    if actors:
        out.document["actors"] = actors
    criteria = {k: _plain(v) for k, v in scenario.criteria.items}
    if criteria:
        out.document["criteria"] = criteria
    return out


def _r(x: float) -> float:
    return round(float(x), RADIUS_DIGITS) + 0.0


def _kph(speed: float) -> float:
    return _r(speed / MPS_PER_KPH)


def _plain(value: object) -> object:
    """A criteria setting as YAML writes it."""
    if isinstance(value, tuple):
        return list(value)
    if hasattr(value, "model_dump"):
        return value.model_dump()
    return value


def _duration(scenario: Scenario, out: Conversion) -> float:
    board = scenario.story.scenario.storyboard if scenario.story is not None else None
    trigger = board.stop_trigger if board is not None else None
    if trigger is not None and len(trigger.groups) == 1 and \
            len(trigger.groups[0].conditions) == 1:
        (c,) = trigger.groups[0].conditions
        if isinstance(c.kind, SimulationTimeCondition) and c.kind.rule in (
                "greaterThan", "greaterOrEqual"):
            return _r(c.kind.value + c.delay)
    out.misfits.append(f"the StopTrigger (not one SimulationTime condition): duration is the "
                       f"time limit, {scenario.duration:g} s")
    return _r(scenario.duration)


def _segments(road: RoadSpec) -> tuple[list[dict[str, Any]], float]:
    """The road's segments as the YAML writes them, and how far [m] at most a curve too
    gentle for its arcs (radius over MAX_RADIUS, written straight) strays: its sagitta."""
    segments: list[dict[str, Any]] = []
    flattened = 0.0
    for seg in road.segments:
        gentle = seg.curvature != 0.0 and 1.0 / abs(seg.curvature) > MAX_RADIUS
        if gentle:
            flattened = max(flattened, abs(seg.curvature) * seg.length ** 2 / 8.0)
        if seg.curvature == 0.0 or gentle:
            if segments and "straight" in segments[-1]:
                segments[-1]["straight"] = _r(segments[-1]["straight"] + seg.length)
            else:
                segments.append({"straight": _r(seg.length)})
        else:
            angle = math.degrees(seg.curvature * seg.length)
            segments.append({"arc": {"radius": _r(1.0 / abs(seg.curvature)),
                                     "angle_deg": _r(angle)}})
        if seg.speed_limit is not None and seg.speed_limit != road.speed_limit:
            segments[-1]["speed_limit_kph"] = _kph(seg.speed_limit)
    return segments, flattened


def _road(road: RoadSpec, out: Conversion) -> dict[str, Any]:
    first = road.segments[0]
    segments, flattened = _segments(road)
    if flattened > 0.0:
        out.misfits.append(f"curves of radius over {MAX_RADIUS:.0f} m (the YAML's largest arc) "
                           f"written straight: at most {flattened:.2f} m off the road's line")
    if any(seg.curvature != 0.0 for seg in road.segments):
        out.misfits.append(f"the road's curves: {len(segments)} straight and arc segments, "
                           "an OpenDRIVE clothoid or cubic as arcs within 1 mm of it")
    if first.paint is not None:
        out.misfits.append("the road's marks (the YAML road paints its own lines)")
    if any(seg.profile is not None or (seg.lane_width, seg.shoulder)
           != (first.lane_width, first.shoulder) for seg in road.segments):
        out.misfits.append("the road's lane widths that change along it (the YAML road has "
                           "one lane width and shoulder: the start's)")
    if first.start is not None and any(first.start):
        out.misfits.append("the road's place in the map frame (the YAML road starts at the "
                           "origin, heading +x)")
    width = first.lane_width
    if width > MAX_LANE_WIDTH:
        out.misfits.append(f"the road's lane width {width:g} m (a test track's: the YAML's "
                           f"lanes are at most {MAX_LANE_WIDTH:g} m wide, written as that)")
        width = MAX_LANE_WIDTH
    return {"lanes": first.lanes, "oncoming_lanes": first.oncoming_lanes,
            "lane_width": _r(width), "shoulder": _r(first.shoulder),
            "speed_limit_kph": _kph(road.speed_limit), "segments": segments}


def _scenery(scenario: Scenario, out: Conversion) -> None:
    """The scenery roads (a dual carriageway's far side) and objects: the YAML has none."""
    for road in scenario.world.scenery_roads:
        lanes = road.segments[0].lanes
        out.misfits.append(f"the road's far carriageway ({lanes} lanes beyond the median, "
                           "drawn as scenery): the YAML road has no scenery roads, it is "
                           "not drawn")
    if scenario.world.scenery_objects:
        out.misfits.append(f"the road's {len(scenario.world.scenery_objects)} static objects "
                           "(poles, trees, guard rails: solids the car may hit): the YAML "
                           "road has none, they are not built")


def _actor(actor: ActorSpec, out: Conversion) -> dict[str, Any]:
    doc: dict[str, Any] = {"id": actor.id, "type": actor.type.value, "lane": actor.lane,
                           "s": _r(actor.s)}
    if actor.offset:
        doc["offset"] = _r(actor.offset)
    doc["speed_kph"] = _kph(actor.speed)
    if actor.model is not None:
        doc["model"] = _nearest_model(actor.model, out, actor.id)
    elif actor.size is not None:
        out.misfits.append(f"actor {actor.id}: its box {_box(actor.size)} m (the YAML's "
                           f"{actor.type.value} has its own)")
    return doc


def _box(size: tuple[float, float, float]) -> str:
    return " x ".join(f"{x:g}" for x in size)


def _nearest_model(model: VehicleModel, out: Conversion, name: str) -> str:
    """The catalogue model nearest the file's box (same class, nearest length)."""
    same = [m for m in CATALOGUE.values() if m.cls is model.cls] or list(CATALOGUE.values())
    best = min(same, key=lambda m: abs(m.length - model.length) + abs(m.width - model.width))
    box = (model.length, model.width, model.height)
    if (best.length, best.width, best.height) != box:
        out.misfits.append(f"actor {name}: its box {_box(box)} m, as the catalogue's "
                           f"{best.name} ({_box((best.length, best.width, best.height))} m)")
    return best.name


def _story(scenario: Scenario, names: dict[str, int], actors: list[dict[str, Any]],
           out: Conversion) -> None:
    """The storyboard's events as the actors' actions (module doc)."""
    story = scenario.story
    assert story is not None
    board = story.scenario.storyboard
    for action in board.init_global:
        out.misfits.append(f"the Init's {type(action).__name__} (no YAML counterpart)")
    index: dict[str, tuple[str, int]] = {}  # action name -> (actor, its index in actions)
    for s in board.stories:
        for act in s.acts:
            _act_start(act.start_trigger, act.name, out)
            for group in act.maneuver_groups:
                for maneuver in group.maneuvers:
                    for event in maneuver.events:
                        _event(event, group.actors.entities, story.ego, names, actors, index,
                               scenario, out)


def _act_start(trigger: Trigger | None, name: str, out: Conversion) -> None:
    if trigger is None:
        return
    times = [c.kind for g in trigger.groups for c in g.conditions]
    if not all(isinstance(k, SimulationTimeCondition) and k.value == 0.0 for k in times):
        out.misfits.append(f"act {name}: its start trigger (the YAML's actions start at once)")


def _event(event: Event, entities: tuple[str, ...], ego: str, names: dict[str, int],
           actors: list[dict[str, Any]], index: dict[str, tuple[str, int]],
           scenario: Scenario, out: Conversion) -> None:
    for action in event.actions:
        private = action.private_action
        if isinstance(private, ActivateControllerAction | AssignControllerAction):
            continue  # the stack drives the car under test from the start
        if isinstance(private, EnvironmentAction | VariableAction):
            out.misfits.append(f"action {action.name}: {type(private).__name__} (no YAML "
                               "counterpart)")
            continue
        if len(entities) != 1 or entities[0] == ego or entities[0] not in names:
            out.misfits.append(f"action {action.name}: not on one actor")
            continue
        actor = actors[names[entities[0]]]
        trigger = _trigger(event, actor["id"], ego, index, out)
        body = _action(private, action.name, actor, scenario, out)
        if trigger is None or body is None:
            continue
        actions = actor.setdefault("actions", [])
        index[action.name] = (actor["id"], len(actions))
        actions.append({"trigger": trigger, **body})
        out.converted.append(action.name)


def _trigger(event: Event, actor: str, ego: str, index: dict[str, tuple[str, int]],
             out: Conversion) -> dict[str, Any] | None:
    trigger = event.start_trigger
    if trigger is None:
        return {"time": 0.0}
    if len(trigger.groups) != 1 or len(trigger.groups[0].conditions) != 1:
        out.misfits.append(f"event {event.name}: a trigger of several conditions")
        return None
    (c,) = trigger.groups[0].conditions
    found = _condition(c, actor, ego, index)
    if found is None:
        out.misfits.append(f"event {event.name}: its {type(c.kind).__name__}")
    return found


def _condition(c: Condition, actor: str, ego: str,
               index: dict[str, tuple[str, int]]) -> dict[str, Any] | None:
    kind = c.kind
    if isinstance(kind, SimulationTimeCondition) and kind.rule in ("greaterThan",
                                                                    "greaterOrEqual"):
        return {"time": _r(kind.value + c.delay)}
    triggering = c.triggering_entities.entities if c.triggering_entities is not None else ()
    if (isinstance(kind, RelativeDistanceCondition) and kind.distance_type == "longitudinal"
            and kind.freespace and kind.rule in ("lessThan", "lessOrEqual")
            and kind.entity.lower() == actor and triggering == (ego,) and c.delay == 0.0):
        return {"gap": _r(kind.value)}
    if (isinstance(kind, StoryboardElementStateCondition) and kind.element_type == "action"
            and kind.state in ENDED and index.get(kind.element_ref, ("", 0))[0] == actor):
        return {"after": index[kind.element_ref][1], "delay": _r(c.delay)}
    return None


def _action(private: object, name: str, actor: dict[str, Any], scenario: Scenario,
            out: Conversion) -> dict[str, Any] | None:
    if isinstance(private, SpeedAction):
        return _speed(private, name, actor, scenario, out)
    if isinstance(private, LaneChangeAction):
        return _lane_change(private, name, actor, scenario, out)
    out.misfits.append(f"action {name}: {type(private).__name__}")
    return None


def _speed(action: SpeedAction, name: str, actor: dict[str, Any], scenario: Scenario,
           out: Conversion) -> dict[str, Any] | None:
    target = action.target
    if isinstance(target, AbsoluteTargetSpeed):
        speed = target.value
    elif isinstance(target, RelativeTargetSpeed) and not target.continuous and \
            target.entity == (scenario.story.ego if scenario.story else ""):
        ego = scenario.world.ego.speed
        speed = ego + target.value if target.value_type == "delta" else ego * target.value
        out.misfits.append(f"action {name}: relative to the car under test's Init speed "
                           f"({_kph(ego):g} km/h), not its speed then")
    else:
        out.misfits.append(f"action {name}: a speed relative to another entity")
        return None
    d = action.dynamics
    body: dict[str, Any] = {"kph": _kph(speed)}
    change = speed - _speed_before(actor) * MPS_PER_KPH  # [m/s]
    if d.shape == "step" or change == 0.0:
        return {"speed": body}
    if d.shape != "linear":
        out.misfits.append(f"action {name}: its {d.shape} shape, as linear")
    # the YAML's accel is signed: negative when it slows (a deceleration's rate is not)
    if d.dimension == "rate" and d.value > 0.0:
        body["accel"] = _r(math.copysign(d.value, change))
    elif d.dimension == "time" and d.value > 0.0:
        body["accel"] = _r(change / d.value)
    else:
        out.misfits.append(f"action {name}: its dynamics ({d.dimension} {d.value:g})")
        return None
    return {"speed": body}


def _speed_before(actor: dict[str, Any]) -> float:
    """[km/h] the actor's speed before its next action, as the YAML format takes it: the
    target of its last speed action so far, else its starting speed."""
    speeds = [a["speed"]["kph"] for a in actor.get("actions", ()) if "speed" in a]
    return float(speeds[-1]) if speeds else float(actor["speed_kph"])


def _lane_change(action: LaneChangeAction, name: str, actor: dict[str, Any],
                 scenario: Scenario, out: Conversion) -> dict[str, Any] | None:
    story = scenario.story
    assert story is not None
    target = action.target
    if isinstance(target, AbsoluteTargetLane) and int(target.value) in story.lane_ids:
        lane = story.lane_ids.index(int(target.value))
    elif isinstance(target, RelativeTargetLane) and target.entity == story.ego:
        lane = scenario.world.ego.lane + target.value
        out.misfits.append(f"action {name}: relative to the car under test's starting lane")
    else:
        out.misfits.append(f"action {name}: its target lane")
        return None
    d = action.dynamics
    if d.dimension != "rate" or action.target_lane_offset:
        out.misfits.append(f"action {name}: its dynamics by {d.dimension} or a lane offset")
        return None
    if d.shape != "linear":
        out.misfits.append(f"action {name}: its {d.shape} shape, as the YAML's trapezoid at "
                           "the same peak lateral speed")
    return {"lane_change": {"to_lane": lane, "lateral_speed": _r(d.value)}}
