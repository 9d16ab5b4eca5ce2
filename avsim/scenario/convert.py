"""Conversion of a validated scenario file into what the run is built from.

The file's units become SI (km/h into m/s, degrees into radians), every default is
resolved, an arc becomes a signed curvature `sign(angle_deg) / radius` and a length
`radius x |angle|`, and each segment's lane layout is resolved from the road's defaults.
In a town each car's `start` and `route` compile into its own route road
(`world.map.town`); the ego's is the scenario's road. The checks that span several keys
(`avsim.scenario.checks`) run here, between the steps whose results they need.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

from avsim.criteria.registry import CriteriaSettings, setting_keys
from avsim.scenario.checks import (
    DEFAULT_SPEED_UP,
    check_road,
    check_spawn,
    check_town,
    given_or,
    speed_accels,
)
from avsim.scenario.errors import LocatedError
from avsim.scenario.model import (
    ActionModel,
    ActorModel,
    CrosswalkFeature,
    EventModel,
    FeatureModel,
    GnssModel,
    RoadModel,
    ScenarioModel,
    SegmentModel,
    SensorsModel,
    SpeedBumpFeature,
    SpeedLimitFeature,
    StackModel,
    StopSignFeature,
    TrafficLightFeature,
    TriggerModel,
)
from avsim.scenario.scenario import DriverSettings, Scenario
from avsim.stack.choice import StackChoice
from world import frames, hdmap, spec
from world.actors.catalogue import CATALOGUE, DEFAULT_MODEL, VehicleModel
from world.frames import MPS_PER_KPH
from world.map.town import TownError, TownLayout, compile_route

TOWN_START_S = 5.0  # [m] default station of a car on its town route (past the start mouth)


def convert(model: ScenarioModel) -> Scenario:
    """Check what spans several keys and convert the validated model into a scenario."""
    if model.road is None:
        return _convert_town(model)
    road_spec = _road_spec(model.road)
    check_road(model, model.road, road_spec.segments)
    scenario = _scenario(model, road_spec,
                         tuple(_actor_spec(i, actor) for i, actor in enumerate(model.actors)))
    check_spawn(scenario.world)
    return scenario


def _kph(value: float) -> float:
    """[m/s] of a speed in km/h."""
    return value * MPS_PER_KPH


def _segment_spec(segment: SegmentModel, road: RoadModel) -> spec.SegmentSpec:
    """A segment in SI: an arc's curvature and length, the road's defaults for its layout."""
    if segment.arc is not None:
        angle = math.radians(segment.arc.angle_deg)
        length = segment.arc.radius * abs(angle)
        curvature = math.copysign(1.0 / segment.arc.radius, angle)
    else:
        length, curvature = float(given_or(segment.straight, 0.0)), 0.0
    limit = segment.speed_limit_kph
    lanes = given_or(segment.lanes, road.lanes)
    oncoming = given_or(segment.oncoming_lanes, road.oncoming_lanes)
    return spec.SegmentSpec(
        length=length,
        curvature=curvature,
        lanes=lanes,
        oncoming_lanes=oncoming,
        lane_width=road.lane_width,
        shoulder=given_or(segment.shoulder, road.shoulder),
        speed_limit=None if limit is None else _kph(limit),
        zone=None if segment.zone is None else hdmap.Zone(segment.zone),
        exit=None if segment.exit is None else hdmap.Side(segment.exit),
        paint=_broken_centre(lanes, oncoming) if road.centre_line == "broken" else None,
    )


PAINT_WIDTH = 0.15  # [m] a painted line's width (`world.scene.road_mesh.LINE_WIDTH`)


def _broken_centre(lanes: int, oncoming: int) -> hdmap.LinePaint | None:
    """The paint of a road whose centre line is one broken yellow line: the road's own
    lines otherwise (solid white edges, broken white between lanes); None without oncoming
    lanes (no centre line)."""
    if oncoming == 0:
        return None
    solid = hdmap.LineMark(hdmap.MarkKind.SOLID, PAINT_WIDTH)
    broken = hdmap.LineMark(hdmap.MarkKind.BROKEN, PAINT_WIDTH)
    centre = hdmap.LineMark(hdmap.MarkKind.BROKEN, PAINT_WIDTH, hdmap.PaintColour.YELLOW)
    return hdmap.LinePaint(solid, (broken,) * (lanes - 1), centre,
                           (broken,) * (oncoming - 1) + (solid,))


def _feature_spec(feature: FeatureModel) -> spec.FeatureSpec:
    """A road feature in SI (a traffic light with its signal plan)."""
    if isinstance(feature, SpeedLimitFeature):
        return hdmap.SpeedLimitSign(s=feature.s, limit=_kph(feature.kph))
    if isinstance(feature, StopSignFeature):
        return hdmap.StopSign(s=feature.s)
    if isinstance(feature, CrosswalkFeature):
        return hdmap.Crosswalk(s=feature.s, width=feature.width)
    if isinstance(feature, SpeedBumpFeature):
        return hdmap.SpeedBump(
            s=feature.s,
            height=feature.height,
            length=feature.length,
            pass_speed=_kph(feature.pass_kph),
        )
    assert isinstance(feature, TrafficLightFeature)
    return spec.TrafficLightSpec(
        s=feature.s,
        green=feature.green,
        yellow=feature.yellow,
        red=feature.red,
        phase=feature.phase,
    )


def _road_spec(road: RoadModel) -> spec.RoadSpec:
    """The route road of a file's `road`."""
    buildings = road.buildings
    return spec.RoadSpec(
        segments=tuple(_segment_spec(segment, road) for segment in road.segments),
        speed_limit=_kph(road.speed_limit_kph),
        features=tuple(_feature_spec(feature) for feature in road.features),
        buildings=None
        if buildings is None
        else spec.BuildingsSpec(density=buildings.density, setback=buildings.setback),
    )


def _trigger_spec(trigger: TriggerModel) -> spec.Trigger:
    """The trigger of the file's one trigger key."""
    kind = trigger.kind
    if kind == "time":
        return spec.TimeTrigger(time=float(given_or(trigger.time, 0.0)))
    if kind == "ego_s":
        return spec.EgoStationTrigger(s=float(given_or(trigger.ego_s, 0.0)))
    if kind == "gap":
        return spec.GapTrigger(gap=float(given_or(trigger.gap, 0.0)))
    return spec.AfterTrigger(index=given_or(trigger.after, 0),
                             delay=float(given_or(trigger.delay, 0.0)))


def _action_spec(action: ActionModel, accel: float | None) -> spec.Action:
    """An action in SI; `accel` [m/s^2] is a speed action's signed acceleration
    (`speed_accels`), of which the spec keeps the magnitude."""
    if action.speed is not None:
        magnitude = abs(given_or(accel, DEFAULT_SPEED_UP))
        return spec.SpeedAction(speed=_kph(action.speed.kph), accel=magnitude)
    if action.lane_change is not None:
        return spec.LaneChangeAction(
            to_lane=action.lane_change.to_lane, lateral_speed=action.lane_change.lateral_speed
        )
    if action.walk is not None:
        return spec.WalkAction(to_offset=action.walk.to_offset, speed=_kph(action.walk.speed_kph))
    assert action.stop is not None
    return spec.StopAction(decel=action.stop.decel)


def _actor_spec(index: int, actor: ActorModel) -> spec.ActorSpec:
    """An actor in SI with its actions (`index`: its place in the file, for errors)."""
    accels = speed_accels(f"actors.{index}", actor)
    actions = tuple(
        spec.ActionSpec(
            trigger=_trigger_spec(action.trigger), action=_action_spec(action, accels.get(number)),
            optional=action.optional,
        )
        for number, action in enumerate(actor.actions)
    )
    return spec.ActorSpec(
        id=actor.id,
        type=spec.ActorType(actor.type),
        lane=given_or(actor.lane, 0),
        s=float(given_or(actor.s, 0.0)),
        offset=actor.offset,
        speed=_kph(actor.speed_kph),
        actions=actions,
        model=_vehicle_model(actor),
    )


def _vehicle_model(actor: ActorModel) -> VehicleModel | None:
    """A vehicle's catalogue model: its own, else its type's default; None: not a vehicle."""
    if actor.model is not None:
        return CATALOGUE[actor.model]
    default = DEFAULT_MODEL.get(actor.type)
    return None if default is None else CATALOGUE[default]


def _event_spec(event: EventModel) -> spec.EventSpec:
    """An ego event and its trigger."""
    trigger = _trigger_spec(event.trigger)
    if event.accelerator_override is not None:
        override = event.accelerator_override
        return spec.EventSpec(
            trigger, spec.AcceleratorOverride(pedal=override.pedal, duration=override.duration),
            event.optional,
        )
    if event.flat_tire is not None:
        return spec.EventSpec(trigger, spec.FlatTire(wheel=frames.Wheel(event.flat_tire.wheel)),
                              event.optional)
    return spec.EventSpec(trigger, _fault_spec(event), event.optional)


def _fault_spec(event: EventModel) -> spec.SensorFault:
    """A sensor fault event's fault."""
    if event.camera_blackout is not None:
        return spec.CameraBlackout(event.camera_blackout.camera, event.camera_blackout.duration)
    if event.camera_freeze is not None:
        return spec.CameraFreeze(event.camera_freeze.camera, event.camera_freeze.duration)
    if event.camera_occlusion is not None:
        occlusion = event.camera_occlusion
        return spec.CameraOcclusion(occlusion.camera, occlusion.fraction,
                                    hdmap.Side(occlusion.side), occlusion.duration)
    if event.sensor_delay is not None:
        delay = event.sensor_delay
        return spec.SensorDelay(delay.sensor, delay.delay, delay.duration)
    if event.lidar_outage is not None:
        return spec.LidarOutage(event.lidar_outage.duration)
    if event.gnss_outage is not None:
        return spec.GnssOutage(event.gnss_outage.duration)
    assert event.gnss_jump is not None
    offset = event.gnss_jump.offset
    return spec.GnssJump((float(offset[0]), float(offset[1])), event.gnss_jump.duration)


def _gnss_spec(gnss: GnssModel | None) -> spec.GnssSpec:
    """The GNSS receiver: the `consumer` preset without a `gnss:` block; else the block's
    preset (`rtk` if it names none) with the knobs it gives in place of the preset's."""
    if gnss is None:
        return spec.GNSS_PRESETS["consumer"]
    base = spec.GNSS_PRESETS[gnss.preset or "rtk"]
    knobs: dict[str, Any] = {
        "sigma": gnss.sigma,
        "heading_sigma": None if gnss.heading_sigma_deg is None
        else math.radians(gnss.heading_sigma_deg),
        "bias": None if gnss.bias is None else (float(gnss.bias[0]), float(gnss.bias[1])),
        "bias_sigma": gnss.bias_sigma,
        "bias_tau": gnss.bias_tau,
        "velocity_sigma": gnss.velocity_sigma,
        "dropout_rate": gnss.dropout_rate,
        "dropout_duration": gnss.dropout_duration,
    }
    return replace(base, **{k: v for k, v in knobs.items() if v is not None})


def sensors_spec(sensors: SensorsModel) -> spec.SensorsSpec:
    """The sensors' noise, the defaults where the file gives none."""
    lidar = sensors.lidar
    return spec.SensorsSpec(
        gnss=_gnss_spec(sensors.gnss),
        lidar=spec.LidarNoiseSpec()
        if lidar is None
        else spec.LidarNoiseSpec(range_sigma=lidar.range_sigma, dropout=lidar.dropout),
    )


def _scenario(model: ScenarioModel, road_spec: spec.RoadSpec,
              actors: tuple[spec.ActorSpec, ...],
              town: spec.TownSpec | None = None) -> Scenario:
    """The scenario of a checked model, its route road and its actors."""
    ego = model.ego
    world = spec.WorldSpec(
        road=road_spec,
        ego=spec.EgoSpec(
            lane=given_or(ego.lane, 0),
            s=float(given_or(ego.s, 0.0)) if town is None else given_or(ego.s, TOWN_START_S),
            speed=_kph(ego.speed_kph),
            max_speed=_kph(ego.max_speed_kph),
        ),
        seed=model.seed,
        actors=actors,
        sensors=sensors_spec(model.sensors),
        events=tuple(_event_spec(event) for event in model.events),
        town=town,
    )
    return Scenario(
        name=model.name,
        description=model.description,
        situation=model.situation,
        duration=float(model.duration),
        world=world,
        driver=DriverSettings(set_speed=_kph(ego.set_speed_kph), overtake=ego.overtake),
        stack=stack_choice(model.stack),
        criteria=CriteriaSettings.of({key: getattr(model.criteria, key)
                                      for key in setting_keys()}),
        grid=tuple((key, tuple(values)) for key, values in model.grid.items()),
    )


def stack_choice(m: StackModel) -> StackChoice:
    """The file's `stack:` (the model checked its factories' form)."""
    return StackChoice(m.stack, m.perception, m.planner, m.controller, m.privileged)


def _convert_town(model: ScenarioModel) -> Scenario:
    """A town: each car's `start` and `route` compile into its own route road
    (`world.map.town`); the ego's is the scenario's `road`."""
    assert model.town is not None  # the model has exactly one map
    t = model.town
    town = spec.TownSpec(t.blocks_x, t.blocks_y, float(t.block), t.lanes, float(t.lane_width),
                         _kph(t.speed_limit_kph), t.junctions)
    layout = TownLayout(town)
    try:
        layout.check("town")
        ego_road = _town_route(layout, "ego", model.ego.start, model.ego.route)
        roads = [_town_route(layout, f"actors.{i}", a.start, a.route)
                 for i, a in enumerate(model.actors)]
    except TownError as error:
        raise LocatedError(error.key, error.problem) from None
    check_town(model, ego_road, roads)
    actors = tuple(
        replace(_actor_spec(index, actor), s=given_or(actor.s, TOWN_START_S), road=road)
        for index, (actor, road) in enumerate(zip(model.actors, roads, strict=True)))
    scenario = _scenario(model, ego_road, actors, town)
    check_spawn(scenario.world)
    return scenario


def _town_route(layout: TownLayout, key: str, start: tuple[int, int, str] | None,
                route: Sequence[str] | None) -> spec.RoadSpec:
    """The route road of a car in the town (`key` names it in errors)."""
    if start is None:
        raise LocatedError(f"{key}.start", "required key missing in a town ([ix, iy, heading])")
    turns = tuple(hdmap.Manoeuvre(turn) for turn in (route or ()))
    return compile_route(layout, (start[0], start[1], start[2]), turns, key)

