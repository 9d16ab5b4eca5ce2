"""An OpenSCENARIO file as a scenario the runner takes (`avsim.scenario.scenario.Scenario`):
the same world spec, driver settings and criteria as a YAML file gives, plus the storyboard
(`StoryProgram`) that the director plays (`avsim.run.storyboard`).

- The road: the file's OpenDRIVE roads, linked end to end into one, as the route
  (`world.map.opendrive.route`); positions on any of them are placed on it. A dual
  carriageway's far side is drawn as a scenery road (`WorldSpec.scenery_roads`); the road
  objects stand as static solids (`WorldSpec.scenery_objects`).
- The car under test: the entity named `Ego` (any case), else the first vehicle. Scripted
  (`scripted_ego`, `avsim run --ego scripted`), the file's actions move it as any other
  entity, its controllers not simulated (esmini's `--disable_controllers`). Else avsim's
  stack drives it (its speed and lane changes and pedal overrides are its driver's inputs,
  `avsim.run.storyboard.driver`; any other motion action on it is refused at load,
  `ego_actions`) once its controller is activated (`starts_engaged`: from the start,
  unless a story activates it later or the sidecar's `function: off` says it starts off;
  until then its driver holds its Init speed in its lane), its set speed the Init speed (the
  speed its driver held when the file's controller takes over); avsim's car keeps its
  own body (4.8 x 1.6 m), not the file's bounding box.
- The other entities become the world's actors with the file's bounding boxes: vehicles by
  category (car, van, motorbike, bicycle: a car; truck, bus, trailer, semitrailer: a truck),
  pedestrians, misc objects as obstacles.
- Init: teleports place the entities in order (relative positions refer to entities placed
  before); an entity no teleport places starts where its Init FollowTrajectoryAction's
  trajectory starts (at its initial distance offset); a speed action with a step sets the
  starting speed; a longitudinal distance action without dynamic constraints places its
  entity at the distance (as esmini jumps); every other Init action starts at t = 0
  (`StoryProgram.init_commands`).
- The run lasts until the StopTrigger fires, at most the sidecar's `duration`; the criteria,
  seed and sensor noise come from the sidecar (`sidecar`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from avsim.scenario.checks import check_spawn
from avsim.scenario.errors import LocatedError, ScenarioError
from avsim.scenario.openscenario.actions import engages
from avsim.scenario.openscenario.ego_actions import driver_input, refuse_on_ego
from avsim.scenario.openscenario.entity_actions import AddEntityAction
from avsim.scenario.openscenario.model import (
    AbsoluteTargetSpeed,
    ActivateControllerAction,
    AssignControllerAction,
    Entity,
    FollowTrajectoryAction,
    InitAction,
    LongitudinalDistanceAction,
    MiscObject,
    OpenScenario,
    Pedestrian,
    SpeedAction,
    TeleportAction,
    Vehicle,
)
from avsim.scenario.openscenario.parse import load_openscenario, scenario_roots
from avsim.scenario.openscenario.program import StoryProgram
from avsim.scenario.openscenario.resolve import Pose, PositionError, Resolver, UnplacedError
from avsim.scenario.openscenario.sampling import sample
from avsim.scenario.openscenario.sidecar import load_sidecar, sidecar_path, split_overrides
from avsim.scenario.scenario import DriverSettings, Scenario
from vehicle_urdf.geometry import read_geometry
from world import spec
from world.actors.catalogue import VehicleClass, VehicleModel
from world.hdmap import RoadMap
from world.map.opendrive import OpenDriveError, load_opendrive
from world.map.opendrive.route import OdrRoute, build_route
from world.map.road import MapError, build_road_map

EGO_NAMES = ("ego",)  # the car under test's entity name, compared in lower case
OFFSET_EPS = 1e-3  # [m] a start this close to its lane's centre is on it
TRUCKS = frozenset({"truck", "bus", "trailer", "semitrailer"})
CLASSES = {"truck": VehicleClass.TRUCK, "trailer": VehicleClass.TRUCK,
           "semitrailer": VehicleClass.TRUCK, "bus": VehicleClass.BUS,
           "motorbike": VehicleClass.MOTORBIKE, "bicycle": VehicleClass.MOTORBIKE}


@dataclass
class _Placed:
    """An entity as the Init actions leave it."""

    pose: Pose | None = None
    speed: float = 0.0  # [m/s]


def load_xosc(path: Path, overrides: Mapping[str, object] | None = None,
              criteria_file: Path | None = None, search_paths: Sequence[Path] = (),
              scripted_ego: bool = False) -> Scenario:
    """The scenario of the OpenSCENARIO file `path` (module doc) with `overrides` (the
    file's `parameters.NAME`, the sidecar's keys) and the sidecar `criteria_file` (None:
    `NAME.criteria.yaml` beside it if there is one), its road and catalogs found in its
    folder tree or `search_paths` (`references`); `scripted_ego`: the file's actions move
    the car under test (module doc); `ScenarioError` (one line) for anything it cannot
    run."""
    params, rest = split_overrides(overrides or {})
    roots = scenario_roots(path, search_paths)
    side_file = sidecar_path(path, criteria_file, roots)
    side = load_sidecar(side_file, rest)
    osc = load_openscenario(path, params, search_paths)
    if osc.road_network is None:
        raise ScenarioError(str(path), "RoadNetwork", "no OpenDRIVE LogicFile: avsim needs "
                            "the road")
    route = _route(osc.road_network)
    try:
        road_map = build_road_map(route.spec)
    except MapError as e:
        raise ScenarioError(str(osc.road_network), "(file)", str(e)) from None
    ego = _ego(osc)
    refuse_on_ego(osc, ego.name, scripted_ego)
    placed, deferred = _init(osc, Resolver(route.chain))
    held = _place_added(osc, placed, Resolver(route.chain))
    if not scripted_ego:
        _check_stack_ego(osc, ego.name, deferred)
    ahead = {e.name: _centre_ahead(e, e.name == ego.name and not scripted_ego)
             for e in osc.entities}
    engaged = starts_engaged(osc, ego.name) and not side.function_off
    ego_spec = replace(_ego_spec(path, road_map, ego.name, placed, ahead[ego.name], engaged),
                       scripted=scripted_ego)
    others = [e for e in osc.entities if e.name != ego.name]
    actors = tuple(_actor_spec(path, road_map, e, placed, ahead[e.name],
                               route.layout.lane_ids) for e in others)
    program = StoryProgram(
        scenario=osc, chain=route.chain, ego=ego.name,
        actors=tuple((e.name, i) for i, e in enumerate(others)),
        centre_ahead=tuple(ahead.items()), lane_ids=route.layout.lane_ids,
        init_commands=tuple(deferred), held_out=held,
        ego_box=(ego.object.bbox.length, ego.object.bbox.width) if scripted_ego else None)
    world = spec.WorldSpec(road=route.spec, ego=ego_spec, actors=actors, seed=side.seed,
                           sensors=side.sensors, scenery_roads=route.scenery,
                           scenery_objects=route.objects)
    _check_spawn(path, world, ego.name, [e.name for e in others], held)
    return Scenario(name=_name(path), description=osc.description, situation="openscenario",
                    duration=side.duration, world=world,
                    driver=DriverSettings(set_speed=ego_spec.speed), stack=side.stack,
                    criteria=side.criteria,
                    story=program, sources=_sources(path, osc.road_network, side_file))


def _check_stack_ego(osc: OpenScenario, ego: str, deferred: Sequence[InitAction]) -> None:
    """The stack drives the car under test: of the motion actions on it (Init actions left
    to run, or a story's) only its driver's inputs are played (`driver_input`), besides its
    controller's actions (and global actions, in a maneuver group of any actors); any other
    is refused at load."""
    for item in deferred:
        if item.entity == ego and (problem := driver_input(item.action)) is not None:
            raise ScenarioError(str(osc.path), f"Storyboard.Init.{ego}", problem)
    for group, a in osc.storyboard.story_actions():
        if ego in group.actors.entities \
                and (problem := driver_input(a.private_action)) is not None:
            raise ScenarioError(str(osc.path), f"Storyboard.Action.{a.name}", problem)


def _sources(*files: Path | None) -> tuple[Path, ...]:
    """The files the scenario was read from (its catalogs are `.xosc` files: no command
    writes over an existing one, `avsim.outputs`)."""
    return tuple(f for f in files if f is not None)


def _check_spawn(path: Path, world: spec.WorldSpec, ego: str, others: list[str],
                 held: Sequence[str] = ()) -> None:
    """No two bodies in the world at t = 0 (`held` entities are not) overlap, by the YAML
    format's rule (`checks.check_spawn`: boxes along the lane, the ego's avsim body),
    refused at the later entity by its name."""
    kept = [k for k, name in enumerate(others) if name not in held]
    world = replace(world, actors=tuple(world.actors[k] for k in kept))
    others = [others[k] for k in kept]
    try:
        check_spawn(world)
    except LocatedError as e:
        names = {f"actors.{k} ({world.actors[k].id})": name for k, name in enumerate(others)}
        names["the ego"] = f"the ego ({ego})"
        problem = re.sub(r"actors\.\d+ \([^)]*\)|the ego", lambda m: names[m.group(0)],
                         e.problem)
        entity = others[int(e.key.split(".")[1])]
        raise ScenarioError(str(path), f"Entities.{entity}", problem) from None


def _name(path: Path) -> str:
    """The scenario's name: the file's stem in [a-z0-9_]."""
    return re.sub(r"[^a-z0-9_]+", "_", path.stem.lower()).strip("_") or "openscenario"


def _route(xodr: Path) -> OdrRoute:
    try:
        return build_route(load_opendrive(xodr))
    except OpenDriveError as e:
        key = f"line {e.line}: {e.path}" if e.line is not None and e.path else "(file)"
        raise ScenarioError(e.file, key, e.problem) from None


def _ego(osc: OpenScenario) -> Entity:
    """The car under test (module doc)."""
    named = [e for e in osc.entities if e.name.lower() in EGO_NAMES]
    vehicles = [e for e in osc.entities if isinstance(e.object, Vehicle)]
    chosen = named[0] if named else (vehicles[0] if vehicles else None)
    if chosen is None or not isinstance(chosen.object, Vehicle):
        raise ScenarioError(str(osc.path), "Entities", "no vehicle to be the car under test "
                            "(an entity named Ego, else the first vehicle)")
    return chosen


def _init(osc: OpenScenario, resolver: Resolver) -> tuple[dict[str, _Placed],
                                                         list[InitAction]]:
    """Each entity's start as the Init actions place it, and the actions left to run.

    A placement relative to an entity not yet placed waits until that entity is (esmini
    places the entities a position refers to first: a file's Ego teleported 200 m behind
    an entity whose Init comes after it starts there); what still waits when nothing more
    can be placed (a loop, an entity never placed) is refused."""
    placed = {e.name: _Placed() for e in osc.entities}
    deferred: list[InitAction] = []
    waiting: list[tuple[InitAction, UnplacedError]] = []
    for item in osc.storyboard.init:
        if (problem := _apply(item, placed, osc, resolver, deferred)) is not None:
            waiting.append((item, problem))
    while waiting:
        left = [(item, p) for item, _ in waiting
                if (p := _apply(item, placed, osc, resolver, deferred)) is not None]
        if len(left) == len(waiting):
            item, problem = left[0]
            raise ScenarioError(str(osc.path), f"Storyboard.Init.{item.entity}", str(problem))
        waiting = left
    return placed, deferred


def _place_added(osc: OpenScenario, placed: dict[str, _Placed],
                 resolver: Resolver) -> tuple[str, ...]:
    """The entities no Init action places that a story adds (AddEntityAction): each is
    built where its first AddEntityAction puts it and held out of the world until added (as
    esmini, whose entities without an Init are inactive until then)."""
    held = []
    for _, action in osc.storyboard.story_actions():
        add = action.private_action
        if not isinstance(add, AddEntityAction) or placed[add.entity].pose is not None:
            continue
        poses = {n: p.pose for n, p in placed.items() if p.pose is not None}
        try:
            placed[add.entity].pose = resolver.resolve(add.position, poses)
        except (UnplacedError, PositionError) as e:
            raise ScenarioError(str(osc.path), f"Storyboard.Action[{action.name}]",
                                f"AddEntityAction: {e}") from None
        held.append(add.entity)
    return tuple(held)


def _apply(item: InitAction, placed: dict[str, _Placed], osc: OpenScenario,
           resolver: Resolver, deferred: list[InitAction]) -> UnplacedError | None:
    """Apply one Init action (`_init`); its `UnplacedError` if it must wait."""
    state, action = placed[item.entity], item.action
    try:
        if isinstance(action, TeleportAction):
            poses = {n: p.pose for n, p in placed.items() if p.pose is not None}
            state.pose = resolver.resolve(action.position, poses)
        elif isinstance(action, SpeedAction) and action.dynamics.shape == "step":
            state.speed = _target_speed(action, placed)
        elif (isinstance(action, LongitudinalDistanceAction)
              and action.constraints is None and not action.continuous):
            state.pose = _at_distance(action, placed, osc, resolver)
        elif not isinstance(action, ActivateControllerAction | AssignControllerAction):
            deferred.append(item)
            if isinstance(action, FollowTrajectoryAction) and state.pose is None:
                state.pose = _trajectory_start(action, placed, resolver)
    except UnplacedError as e:
        if isinstance(action, TeleportAction | LongitudinalDistanceAction):
            return e
        raise ScenarioError(str(osc.path), f"Storyboard.Init.{item.entity}", str(e)) from None
    except PositionError as e:
        raise ScenarioError(str(osc.path), f"Storyboard.Init.{item.entity}", str(e)) from None
    return None


def _trajectory_start(action: FollowTrajectoryAction, placed: Mapping[str, _Placed],
                      resolver: Resolver) -> Pose:
    """Where an Init FollowTrajectoryAction puts an entity no teleport has placed: on its
    trajectory at the initial distance offset (0: the start), heading along it, as esmini
    places it when the action starts."""
    poses = {n: p.pose for n, p in placed.items() if p.pose is not None}
    path = sample(action.trajectory.shape, lambda p: resolver.resolve(p, poses))
    return path.at(action.initial_distance_offset or 0.0, 0.0)


def _target_speed(action: SpeedAction, placed: Mapping[str, _Placed]) -> float:
    target = action.target
    if isinstance(target, AbsoluteTargetSpeed):
        return target.value
    ref = placed[target.entity].speed
    return ref + target.value if target.value_type == "delta" else ref * target.value


def _at_distance(action: LongitudinalDistanceAction, placed: Mapping[str, _Placed],
                 osc: OpenScenario, resolver: Resolver) -> Pose:
    """Where a longitudinal distance action in Init puts its entity: at the distance (or
    the time gap at the referenced entity's speed) ahead of it, or behind it for
    `trailingReferencedEntity`, along the road, keeping its own lateral place."""
    ref = placed[action.entity]
    if ref.pose is None:
        raise UnplacedError(f"entity {action.entity} has no position yet")
    gap = action.distance if action.distance is not None else (action.time_gap or 0.0) * ref.speed
    if action.freespace:
        gap += 0.5 * (_length(osc.entity(action.entity)) + _length(_owner(osc, action)))
    sign = -1.0 if action.displacement == "trailingReferencedEntity" else 1.0
    s_ref, _ = resolver.road_coordinates(ref.pose.x, ref.pose.y)
    own = placed[_owner(osc, action).name].pose
    t = resolver.road_coordinates(own.x, own.y)[1] if own is not None else (
        resolver.road_coordinates(ref.pose.x, ref.pose.y)[1])
    s = s_ref + sign * gap
    return resolver.road_pose(s, t, resolver.lane_id(s, t), None)


def _owner(osc: OpenScenario, action: LongitudinalDistanceAction) -> Entity:
    for item in osc.storyboard.init:
        if item.action is action:
            return osc.entity(item.entity)
    raise KeyError("distance action without an entity")


def _length(entity: Entity) -> float:
    return entity.object.bbox.length


def _centre_ahead(entity: Entity, is_ego: bool) -> float:
    """[m] the body's centre ahead of the entity's reference point."""
    if is_ego:
        return read_geometry().rear_axle
    return entity.object.bbox.center_x


def _centre(path: Path, road_map: RoadMap, name: str, placed: Mapping[str, _Placed],
            ahead: float) -> tuple[int | None, float, float]:
    """(route lane, station, offset from that lane's centre) of the entity's body centre."""
    pose = placed[name].pose
    if pose is None:
        raise ScenarioError(str(path), "Storyboard.Init", f"entity {name} is never placed "
                            "(no TeleportAction in Init)")
    xy = (pose.x + ahead * math.cos(pose.heading), pose.y + ahead * math.sin(pose.heading))
    return road_map.lane_at(xy)


def starts_engaged(osc: OpenScenario, ego: str) -> bool:
    """Whether the stack drives the car under test `ego` from the start (module doc): unless
    a story activates its controller (`engages`) and no Init action has already."""
    controller = ActivateControllerAction | AssignControllerAction
    if any(item.entity == ego and isinstance(item.action, controller)
           and engages(item.action, False) for item in osc.storyboard.init):
        return True
    return not any(
        ego in group.actors.entities and isinstance(a.private_action, controller)
        and engages(a.private_action, False)
        for group, a in osc.storyboard.story_actions())


def _ego_spec(path: Path, road_map: RoadMap, name: str, placed: Mapping[str, _Placed],
              ahead: float, engaged: bool) -> spec.EgoSpec:
    lane, s, r = _centre(path, road_map, name, placed, ahead)
    if lane is None or lane < 0:
        raise ScenarioError(str(path), f"Storyboard.Init.{name}", "the car under test must "
                            "start in a driving lane of the road's right-hand carriageway")
    return spec.EgoSpec(lane=lane, s=s, speed=placed[name].speed,
                        max_speed=max(placed[name].speed, 180.0 / 3.6),
                        engaged=engaged, offset=r if abs(r) > OFFSET_EPS else 0.0)


def _actor_spec(path: Path, road_map: RoadMap, entity: Entity,
                placed: Mapping[str, _Placed], ahead: float,
                lane_ids: tuple[int, ...]) -> spec.ActorSpec:
    lane, s, r = _centre(path, road_map, entity.name, placed, ahead)
    if lane is None:  # off the lanes (a pedestrian on the verge): from the nearest lane
        lane, r = _nearest_lane(road_map, s, r)
    named = _named_lane(placed[entity.name].pose, lane_ids)
    if named is not None and named != lane:  # its lane as the position named it (esmini's)
        r += float(road_map.lane(lane).offset_at(s) - road_map.lane(named).offset_at(s))
        lane = named
    obj = entity.object
    base = spec.ActorSpec(id=_actor_id(entity.name), type=spec.ActorType.OBSTACLE, lane=lane,
                          s=s, offset=r, speed=placed[entity.name].speed,
                          against=isinstance(obj, Vehicle) and _against(
                              road_map, lane, s, placed[entity.name].pose))
    if isinstance(obj, Vehicle):
        kind = spec.ActorType.TRUCK if obj.category in TRUCKS else spec.ActorType.CAR
        return replace(base, type=kind, model=_model(obj))
    size = (obj.bbox.length, obj.bbox.width, obj.bbox.height)
    if isinstance(obj, Pedestrian):
        return replace(base, type=spec.ActorType.PEDESTRIAN, size=size,
                       facing=_facing(road_map, lane, s, placed[entity.name].pose))
    assert isinstance(obj, MiscObject)
    return replace(base, size=size)


def _named_lane(pose: Pose | None, lane_ids: tuple[int, ...]) -> int | None:
    """The route lane a lane position placed the entity in (its OpenDRIVE lane, even where
    the offset puts it over the border), None for other positions or a lane off the route."""
    if pose is None or pose.lane_id is None or pose.lane_id not in lane_ids:
        return None
    return lane_ids.index(pose.lane_id)


def _against(road_map: RoadMap, lane: int, s: float, pose: Pose | None) -> bool:
    """Whether a vehicle placed with `pose` heads against its lane's direction of travel
    (a heading more than a quarter turn from it, e.g. a relative orientation of half a turn
    in a lane position: relative to the lane's direction, as esmini reads it)."""
    if pose is None:
        return False
    travel = float(road_map.heading_at(s)) + (0.0 if road_map.lane(lane).direction > 0
                                              else math.pi)
    return math.cos(pose.heading - travel) < 0.0


def _facing(road_map: RoadMap, lane: int, s: float, pose: Pose | None) -> float:
    """[rad] the heading of `pose` from the direction of travel of `lane` at station `s`
    [m], left positive, within a half turn (0 without a pose)."""
    if pose is None:
        return 0.0
    travel = float(road_map.heading_at(s)) + (0.0 if road_map.lane(lane).direction > 0
                                              else math.pi)
    return math.remainder(pose.heading - travel, math.tau)


def _nearest_lane(road_map: RoadMap, s: float, d: float) -> tuple[int, float]:
    """(route lane nearest to offset d [m] from the reference line at s, offset from it)."""
    lanes = range(road_map.lanes_at(s))
    best = min(lanes, key=lambda i: abs(d - float(road_map.lane(i).offset_at(s))))
    return best, d - float(road_map.lane(best).offset_at(s))


def _actor_id(name: str) -> str:
    return re.sub(r"[^a-z0-9_]+", "_", name.lower()).strip("_") or "entity"


def _wheelbase(vehicle: Vehicle) -> float:
    """[m] front axle to rear axle; with no front axle (a trailer) the rear axle to the
    box's front end, where a trailer's drawbar pivots."""
    if vehicle.front_axle is not None:
        return vehicle.front_axle.position_x - vehicle.rear_axle.position_x
    box = vehicle.bbox
    return box.center_x + box.length / 2.0 - vehicle.rear_axle.position_x


def _model(vehicle: Vehicle) -> VehicleModel:
    """A vehicle's body from the file: its bounding box and axles."""
    box = vehicle.bbox
    return VehicleModel(
        name=vehicle.name, cls=CLASSES.get(vehicle.category, VehicleClass.CAR),
        length=box.length, width=box.width, height=box.height,
        wheelbase=_wheelbase(vehicle),
        mass=vehicle.mass if vehicle.mass is not None else 0.0,
        source=f"OpenSCENARIO vehicle {vehicle.name} ({vehicle.category})")
