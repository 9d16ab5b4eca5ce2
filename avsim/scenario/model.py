"""Pydantic models of the scenario file format `avsim/1` (the public contract, see
`SCENARIO_FORMAT.md` and `docs/scenario-format.md`).

The models mirror the YAML exactly, key for key, in the file's units (`*_kph` km/h, `*_deg`
degrees, everything else SI). They are strict: unknown keys are rejected, text is never
coerced into a number (an integer is accepted where a float is expected), and every field
carries a description with its unit and default, which the JSON Schema (`avsim schema`)
shows. `avsim.scenario.load` validates a file with `ScenarioModel`
(`avsim.scenario.validation`), applies the cross-field checks (lanes at a station, stations
on the route, ...; `avsim.scenario.checks`) and converts it into a
`avsim.scenario.scenario.Scenario` (SI units, radians, resolved defaults;
`avsim.scenario.convert`).

One-key mappings of the format (a segment `straight:` / `arc:`, a trigger `time:` / ...,
an action `speed:` / ..., an event) are models whose alternatives are optional fields; a
`before` validator names an unknown alternative and an `after` validator demands exactly
one. Such problems are raised as `PydanticCustomError` of type `avsim` whose context holds
the message (`problem`) and optionally the offending key (`key`) below the model's location.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Annotated, Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    StrictBool,
    create_model,
    field_validator,
    model_validator,
)

from avsim.criteria.registry import keyed, setting_keys, switches
from avsim.scenario import bounds as b
from avsim.scenario.fields import (
    FormatModel,
    Fraction,
    problem,
)
from avsim.stack.choice import BUNDLED, MAX_SPEC, SPEC, TRUTH_PERCEPTION
from world.actors.catalogue import CATALOGUE, TYPE_CLASSES

FORMAT = "avsim/1"
NAME_PATTERN = r"^[a-z0-9_]+$"
StackSpec = Annotated[str, Field(max_length=MAX_SPEC, pattern=SPEC.pattern)]  # a factory

Situation = Literal[
    "normal_driving",
    "lane_change",
    "cut_in_out",
    "traffic_jam",
    "sudden_stop",
    "external_disturbance",
    "decs_route",
    "town",
    "other",
]
ZoneName = Literal["highway", "ramp", "city"]
SideName = Literal["right", "left"]
ActorTypeName = Literal["car", "truck", "pedestrian", "obstacle"]
VehicleModelName = Literal[  # `world.actors.catalogue.CATALOGUE`'s names (a test keeps them equal)
    "small_car", "sedan", "suv", "van", "bus", "rigid_truck", "semi_trailer", "motorbike"
]
Junctions = Literal["stop_signs", "traffic_lights", "mixed"]
Heading = Literal["east", "north", "west", "south"]
Turn = Literal["straight", "left", "right", "u_turn"]
WheelName = Literal["front_left", "front_right", "rear_left", "rear_right"]

TRIGGER_KINDS = ("time", "ego_s", "gap", "after")
ACTION_KINDS = ("speed", "lane_change", "walk", "stop")
FAULT_KINDS = ("camera_blackout", "camera_freeze", "camera_occlusion", "lidar_outage",
               "gnss_outage", "gnss_jump", "sensor_delay")
EVENT_KINDS = ("accelerator_override", "flat_tire", *FAULT_KINDS)
CameraName = Literal["front", "left", "right"]
DelayedSensor = Literal["front", "left", "right", "lidar"]

Identifier = Annotated[str, Field(pattern=NAME_PATTERN)]
ScenarioName = Annotated[str, Field(pattern=NAME_PATTERN, max_length=b.MAX_NAME_LENGTH)]  # it
# names the run's files (runs/<name>.rrd, a sweep's <name>_000.rrd): a file name's characters
MAX_GRID_POINTS = 1000  # runs a file's `grid` may ask for
MAX_GRID_VALUES = 100  # values of one grid key
GridPath = Annotated[str, Field(  # a key path, or several joined by commas (values go together)
    pattern=r"^[a-z0-9_]+(\.[a-z0-9_]+)*(, *[a-z0-9_]+(\.[a-z0-9_]+)*)*$")]
GridValues = Annotated[list[Any], Field(min_length=1, max_length=MAX_GRID_VALUES)]


MAX_VARY_KEYS = 100  # keys a file's `vary` may draw
MAX_CHOICES = 100  # values of one `choice`


def grid_paths(key: str) -> list[str]:
    """The key paths of one `grid` key: one, or several joined by commas."""
    return [path.strip() for path in key.split(",")]


def _one_of(names: tuple[str, ...]) -> dict[str, Any]:
    """JSON Schema fragment: exactly one of `names` is present."""
    return {"oneOf": [{"required": [name]} for name in names]}


def _present(model: BaseModel, names: tuple[str, ...]) -> list[str]:
    """Names among `names` whose field is set (not None) on `model`."""
    return [name for name in names if getattr(model, name) is not None]


def _reject_unknown_kind(data: Any, allowed: set[str], kinds: tuple[str, ...], what: str) -> Any:
    """`before` validator body: name a key of a one-key mapping that is not a known kind."""
    if isinstance(data, dict):
        for key in data:
            if key not in allowed:
                expected = ", ".join(kinds)
                raise problem(f"unknown {what} {key!r} (expected one of {expected})")
    return data


def _empty_for_null(data: Any, kinds: tuple[str, ...]) -> Any:
    """`before` validator body: an action or event written without a value (`stop:`) is
    the same as an empty mapping (`stop: {}`)."""
    if isinstance(data, dict):
        return {key: {} if key in kinds and value is None else value for key, value in data.items()}
    return data


def _exactly_one(model: BaseModel, kinds: tuple[str, ...], what: str) -> str:
    """`after` validator body: the one kind set on `model`, else a clear error."""
    present = _present(model, kinds)
    if len(present) != 1:
        listed = ", ".join(kinds)
        if not present:
            raise problem(f"needs one {what} (one of {listed})")
        raise problem(f"has {len(present)} {what}s ({', '.join(present)}); give exactly one")
    return present[0]


# ---------------------------------------------------------------------------------------
# Road
# ---------------------------------------------------------------------------------------


class ArcModel(FormatModel):
    """A constant-curvature arc of the route's reference line (lane 0's centre line)."""

    radius: b.Radius = Field(
        description="[m] radius of the reference line (lane 0's centre line); required, > 0, "
        "and larger than the road's paved width (lanes x lane_width + shoulder)."
    )
    angle_deg: Annotated[float, Field(ge=-360, le=360)] = Field(
        description="[deg] turn angle; > 0 turns left, < 0 turns right; required, != 0, -360..360.",
        json_schema_extra={"not": {"const": 0}},
    )

    @field_validator("angle_deg")
    @classmethod
    def _nonzero(cls, value: float) -> float:
        if value == 0:
            raise problem("must not be 0 (use a straight)")
        return value


class SegmentModel(FormatModel):
    """One piece of the route, `- straight: 300` or `- {arc: {radius, angle_deg}, ...}`."""

    model_config = ConfigDict(json_schema_extra=_one_of(("straight", "arc")))

    straight: b.Length | None = Field(
        default=None, description="[m] length of a straight piece, > 0; give this or `arc`."
    )
    arc: ArcModel | None = Field(
        default=None, description="An arc piece `{radius, angle_deg}`; give this or `straight`."
    )
    lanes: b.Lanes | None = Field(
        default=None,
        description="Driving lanes in the ego's direction on this segment, >= 1. "
        "Default: the road's `lanes`.",
    )
    oncoming_lanes: b.OncomingLanes | None = Field(
        default=None,
        description="Oncoming lanes on this segment, >= 0. Default: the road's `oncoming_lanes`.",
    )
    shoulder: b.Shoulder | None = Field(
        default=None,
        description="[m] paved right shoulder on this segment, >= 0. Default: the road's "
        "`shoulder`.",
    )
    speed_limit_kph: b.PosSpeed | None = Field(
        default=None,
        description="[km/h] limit posted at the segment's start, > 0. Default: unchanged "
        "(the limit in force goes on).",
    )
    zone: ZoneName | None = Field(
        default=None,
        description="Scenery style: highway | ramp | city. Default: as the segment before "
        "(highway at the start).",
    )
    exit: SideName | None = Field(
        default=None,
        description="right | left: this segment leaves the road before it by an exit from its "
        "right / left edge; that road goes on straight as scenery (left: not supported "
        "yet). Default: none.",
    )

    @model_validator(mode="after")
    def _one_shape(self) -> SegmentModel:
        _exactly_one(self, ("straight", "arc"), "shape")
        return self


class SpeedLimitFeature(FormatModel):
    """A speed limit sign: the limit applies from its station on."""

    type: Literal["speed_limit"] = Field(description="Feature type `speed_limit`.")
    s: b.Station = Field(description="[m] station of the sign; required, on the route.")
    kph: b.PosSpeed = Field(description="[km/h] the posted limit; required, > 0.")


class StopSignFeature(FormatModel):
    """A stop line across the route with a stop sign on the right."""

    type: Literal["stop_sign"] = Field(description="Feature type `stop_sign`.")
    s: b.Station = Field(description="[m] station of the stop line; required, on the route.")


class CrosswalkFeature(FormatModel):
    """A zebra crossing from `s` to `s + width`."""

    type: Literal["crosswalk"] = Field(description="Feature type `crosswalk`.")
    s: b.Station = Field(description="[m] station of the near edge; required, on the route.")
    width: b.FeatureSize = Field(default=4.0,
                                 description="[m] extent along the route, > 0. Default 4.")


class SpeedBumpFeature(FormatModel):
    """A speed bump across the road."""

    type: Literal["speed_bump"] = Field(description="Feature type `speed_bump`.")
    s: b.Station = Field(description="[m] station of the bump's centre; required, on the route.")
    height: b.BumpHeight = Field(default=0.1, description="[m] height, > 0. Default 0.1.")
    length: b.FeatureSize = Field(
        default=0.9, description="[m] extent along the route, > 0. Default 0.9."
    )
    pass_kph: b.PosSpeed = Field(
        default=5.0, description="[km/h] the speed to take it at, > 0. Default 5."
    )


class TrafficLightFeature(FormatModel):
    """A traffic light with a stop line; a fixed green-yellow-red cycle."""

    type: Literal["traffic_light"] = Field(description="Feature type `traffic_light`.")
    s: b.Station = Field(description="[m] station of the stop line; required, on the route.")
    green: b.Duration = Field(default=20.0, description="[s] green time, > 0. Default 20.")
    yellow: b.Duration = Field(default=3.0, description="[s] yellow time, > 0. Default 3.")
    red: b.Duration = Field(default=15.0, description="[s] red time, > 0. Default 15.")
    phase: b.Time = Field(
        default=0.0, description="[s] time into the cycle (from green) at t = 0, >= 0. Default 0."
    )


FEATURE_TYPES = ("speed_limit", "stop_sign", "crosswalk", "speed_bump", "traffic_light")
FeatureModel = Annotated[
    SpeedLimitFeature | StopSignFeature | CrosswalkFeature | SpeedBumpFeature | TrafficLightFeature,
    Field(discriminator="type"),
]


class BuildingsModel(FormatModel):
    """Scenery buildings along both sides of the road."""

    density: Fraction = Field(
        default=0.5,
        description="[-] built-up fraction of the roadside frontage, 0..1. Default 0.5.",
    )
    setback: b.Setback = Field(
        default=6.0,
        description="[m] from the road's outer paved edge to the building fronts, >= 0. Default 6.",
    )


class RoadModel(FormatModel):
    """Map kind 1: one route road of straight and arc segments laid end to end from the
    origin, heading +x."""

    lanes: b.Lanes = Field(
        default=1,
        description="Driving lanes in the ego's direction, >= 1; lane 0 is the rightmost. "
        "Default 1.",
    )
    oncoming_lanes: b.OncomingLanes = Field(
        default=0,
        description="Lanes in the other direction, left of a yellow centre line, >= 0. Default 0.",
    )
    lane_width: b.LaneWidth = Field(default=3.5, description="[m] lane width, > 0. Default 3.5.")
    shoulder: b.Shoulder = Field(
        default=2.5, description="[m] paved right shoulder, >= 0. Default 2.5."
    )
    centre_line: Literal["solid", "broken"] = Field(
        default="solid",
        description="The centre line between the two directions: solid (a double solid "
        "yellow line, which may not be crossed) | broken (one broken yellow line: a pass "
        "through the oncoming lane is allowed). Default solid.",
    )
    speed_limit_kph: b.PosSpeed = Field(description="[km/h] limit posted at s = 0; required, > 0.")
    segments: list[SegmentModel] = Field(
        min_length=1, max_length=b.MAX_SEGMENTS,
        description="The ego's route, at least one segment; required."
    )
    features: list[FeatureModel] = Field(
        default_factory=list, max_length=b.MAX_FEATURES,
        description="Features at stations along the route, each with a `type`. Default none.",
    )
    buildings: BuildingsModel | None = Field(
        default=None, description="Optional scenery buildings `{density, setback}`. Default none."
    )

    @model_validator(mode="after")
    def _route_length(self) -> RoadModel:
        """The route, its segments' lengths added up, is at most `MAX_ROUTE_LENGTH`."""
        length = sum(seg.straight if seg.straight is not None else
                     seg.arc.radius * math.radians(abs(seg.arc.angle_deg)) if seg.arc else 0.0
                     for seg in self.segments)
        if length > b.MAX_ROUTE_LENGTH:
            raise problem(f"the route is {length:.0f} m long: at most "
                          f"{b.MAX_ROUTE_LENGTH:.0f} m", key="segments")
        return self


class TownModel(FormatModel):
    """Map kind 2: a grid town of two-way streets, junctions, stop signs and lights."""

    blocks_x: b.Blocks = Field(description="Blocks along x, >= 1; required.")
    blocks_y: b.Blocks = Field(description="Blocks along y, >= 1; required.")
    block: b.Block = Field(description="[m] block size (junction spacing), > 0; required.")
    lanes: b.TownLanes = Field(default=1, description="Lanes per direction, >= 1. Default 1.")
    lane_width: b.LaneWidth = Field(default=3.5, description="[m] lane width, > 0. Default 3.5.")
    speed_limit_kph: b.PosSpeed = Field(description="[km/h] limit on every street; required, > 0.")
    junctions: Junctions = Field(
        default="stop_signs",
        description="Junction control: stop_signs | traffic_lights | mixed. Default stop_signs.",
    )


TownStart = Annotated[
    tuple[
        Annotated[int, Field(strict=True, ge=0)], Annotated[int, Field(strict=True, ge=0)], Heading
    ],
    Field(strict=False),  # a YAML list is accepted for the tuple; its items stay strict
]


# ---------------------------------------------------------------------------------------
# Triggers, actions, events
# ---------------------------------------------------------------------------------------


class TriggerModel(FormatModel):
    """When an action or event fires: `{time: t}`, `{ego_s: s}`, `{gap: d}` or
    `{after: i, delay: t}`. It fires once, when it first holds."""

    model_config = ConfigDict(json_schema_extra=_one_of(TRIGGER_KINDS))

    time: b.Time | None = Field(default=None, description="[s] simulated time, >= 0.")
    ego_s: b.Station | None = Field(
        default=None, description="[m] the ego's station reached, >= 0, on the route."
    )
    gap: b.Station | None = Field(
        default=None,
        description="[m] bumper-to-bumper distance from this actor to the ego along the route "
        "falls to this or below, >= 0.",
    )
    after: b.ActionIndex | None = Field(
        default=None,
        description="Index of an EARLIER action of the same actor (or event of the list); "
        "fires `delay` seconds after it ended.",
    )
    delay: b.Time | None = Field(
        default=None, description="[s] with `after` only: wait after that action ended. Default 0."
    )

    @model_validator(mode="before")
    @classmethod
    def _known_kind(cls, data: Any) -> Any:
        allowed = {*TRIGGER_KINDS, "delay"}
        return _reject_unknown_kind(data, allowed, TRIGGER_KINDS, "trigger")

    @model_validator(mode="after")
    def _one_kind(self) -> TriggerModel:
        kind = _exactly_one(self, TRIGGER_KINDS, "trigger")
        if self.delay is not None and kind != "after":
            raise problem("only goes with `after`", key="delay")
        return self

    @property
    def kind(self) -> str:
        """The trigger's kind: one of `TRIGGER_KINDS`."""
        return _present(self, TRIGGER_KINDS)[0]


class SpeedActionModel(FormatModel):
    """Change speed to `kph` at a signed acceleration."""

    kph: b.Speed = Field(description="[km/h] target speed, >= 0; required.")
    accel: b.Accel | None = Field(
        default=None,
        description="[m/s^2] signed acceleration, != 0: > 0 to speed up, < 0 to slow down. "
        "Default 2 when speeding up, -3 when slowing.",
        json_schema_extra={"not": {"const": 0}},
    )

    @field_validator("accel")
    @classmethod
    def _nonzero(cls, value: float | None) -> float | None:
        if value == 0:
            raise problem("must not be 0 (signed: > 0 speeds up, < 0 slows down)")
        return value


class LaneChangeActionModel(FormatModel):
    """Move to another lane at a constant lateral speed."""

    to_lane: int = Field(description="Target lane index; required, must exist.")
    lateral_speed: b.LateralSpeed = Field(
        default=2.0, description="[m/s] lateral speed, > 0. Default 2.0 (UN R157-like)."
    )


class WalkActionModel(FormatModel):
    """Walk across the road to a lateral offset from the actor's lane centre, at a walking
    speed (reached and left at `world.actors.behaviour.LATERAL_ACCEL`), facing the walking
    direction; then stand."""

    to_offset: b.Offset = Field(
        description="[m] lateral offset from the actor's lane centre to walk to, left "
        "positive; required."
    )
    speed_kph: b.PosSpeed = Field(default=5.0, description="[km/h] walking speed, > 0. Default 5.")


class StopActionModel(FormatModel):
    """Brake to a standstill, written `stop: {}`."""

    decel: b.Decel = Field(
        default=6.0, description="[m/s^2] braking deceleration, > 0. Default 6."
    )


class ActionModel(FormatModel):
    """One scripted action of an actor: a `trigger` and exactly one action key."""

    model_config = ConfigDict(json_schema_extra=_one_of(ACTION_KINDS))

    trigger: TriggerModel = Field(description="When the action fires (once); required.")
    speed: SpeedActionModel | None = Field(
        default=None, description="Change speed: `{kph, accel}`."
    )
    lane_change: LaneChangeActionModel | None = Field(
        default=None, description="Change lane: `{to_lane, lateral_speed}`."
    )
    walk: WalkActionModel | None = Field(
        default=None, description="Walk across: `{to_offset, speed_kph}`."
    )
    stop: StopActionModel | None = Field(
        default=None, description="Brake to a stop: `{}` (optional `decel`)."
    )
    optional: StrictBool = Field(
        default=False, description="true: the run may end without it having fired; else it "
        "must fire before the run ends early, and one that never fires fails `story`. "
        "Default false.")

    @model_validator(mode="before")
    @classmethod
    def _known_kind(cls, data: Any) -> Any:
        data = _reject_unknown_kind(data, {"trigger", "optional", *ACTION_KINDS}, ACTION_KINDS,
                                    "action")
        return _empty_for_null(data, ACTION_KINDS)

    @model_validator(mode="after")
    def _one_kind(self) -> ActionModel:
        _exactly_one(self, ACTION_KINDS, "action")
        return self

    @property
    def kind(self) -> str:
        """The action's name: one of `ACTION_KINDS`."""
        return _present(self, ACTION_KINDS)[0]


class AcceleratorOverrideModel(FormatModel):
    """An external disturbance: the accelerator pedal is held at `pedal` for `duration`
    seconds, then released. The car is drive-by-wire: the pedal is a sensor the driving stack
    reads and arbitrates (its speed limiter); the world adds no torque for it."""

    pedal: Fraction = Field(description="[-] pedal position 0..1; required.")
    duration: b.Duration = Field(description="[s] how long, > 0; required.")


class FlatTireModel(FormatModel):
    """A tyre goes flat."""

    wheel: WheelName = Field(
        description="front_left | front_right | rear_left | rear_right; required."
    )


class CameraFaultModel(FormatModel):
    """A camera's fault for `duration` seconds (a camera the profile lacks: nothing happens)."""

    camera: CameraName = Field(description="front | left | right; required.")
    duration: b.FaultDuration = Field(description="[s] how long, > 0; required.")


class CameraOcclusionModel(FormatModel):
    """An opaque dark strip over `fraction` of a camera's image width, from `side`, for
    `duration` seconds (a camera the profile lacks: nothing happens)."""

    camera: CameraName = Field(description="front | left | right; required.")
    fraction: Annotated[float, Field(gt=0, le=1)] = Field(
        default=0.5, description="[-] of the image's width covered, > 0, <= 1. Default 0.5.")
    side: SideName = Field(default="left", description="left | right, as the car looks. "
                           "Default left.")
    duration: b.FaultDuration = Field(description="[s] how long, > 0; required.")


class SensorDelayModel(FormatModel):
    """A sensor's data arrive `delay` seconds later than its latency, for `duration` seconds
    (a camera the profile lacks: nothing happens)."""

    sensor: DelayedSensor = Field(description="front | left | right | lidar; required.")
    delay: b.SensorDelay = Field(description="[s] added to its latency, > 0, <= 1; required.")
    duration: b.FaultDuration = Field(description="[s] how long, > 0; required.")


class OutageModel(FormatModel):
    """A sensor sends nothing usable for `duration` seconds."""

    duration: b.FaultDuration = Field(description="[s] how long, > 0; required.")


class GnssJumpModel(FormatModel):
    """The GNSS fixes jump by `offset` for `duration` seconds."""

    offset: Annotated[
        tuple[Annotated[float, Field(strict=True, ge=-b.MAX_GNSS_JUMP, le=b.MAX_GNSS_JUMP)],
              Annotated[float, Field(strict=True, ge=-b.MAX_GNSS_JUMP, le=b.MAX_GNSS_JUMP)]],
        Field(strict=False),
    ] = Field(description="[m] (x, y) added to every fix, map frame, each within +-1000; "
              "required.")
    duration: b.FaultDuration = Field(description="[s] how long, > 0; required.")


class EventModel(FormatModel):
    """Something that happens to the ego car: a `trigger` (not `gap`: there is no actor)
    and exactly one event key: `accelerator_override`, `flat_tire`, or a sensor fault
    (`camera_blackout`, `camera_freeze`, `camera_occlusion`, `lidar_outage`, `gnss_outage`,
    `gnss_jump`, `sensor_delay`)."""

    model_config = ConfigDict(json_schema_extra=_one_of(EVENT_KINDS))

    trigger: TriggerModel = Field(description="When the event fires (once); required.")
    accelerator_override: AcceleratorOverrideModel | None = Field(
        default=None, description="Hold the accelerator: `{pedal, duration}`."
    )
    flat_tire: FlatTireModel | None = Field(default=None, description="A flat tyre: `{wheel}`.")
    camera_blackout: CameraFaultModel | None = Field(
        default=None, description="A camera's images go black: `{camera, duration}`.")
    camera_freeze: CameraFaultModel | None = Field(
        default=None, description="A camera repeats its last image: `{camera, duration}`.")
    camera_occlusion: CameraOcclusionModel | None = Field(
        default=None, description="A dark strip covers part of a camera's image: "
        "`{camera, fraction, side, duration}`.")
    lidar_outage: OutageModel | None = Field(
        default=None, description="The LiDAR sends no scan: `{duration}`.")
    gnss_outage: OutageModel | None = Field(
        default=None, description="The GNSS receiver has no fix: `{duration}`.")
    gnss_jump: GnssJumpModel | None = Field(
        default=None, description="The GNSS fixes jump by an offset: `{offset, duration}`.")
    sensor_delay: SensorDelayModel | None = Field(
        default=None, description="A sensor's data arrive late: `{sensor, delay, duration}`.")
    optional: StrictBool = Field(
        default=False, description="true: the run may end without it having fired; else it "
        "must fire before the run ends early, and one that never fires fails `story`. "
        "Default false.")

    @model_validator(mode="before")
    @classmethod
    def _known_kind(cls, data: Any) -> Any:
        data = _reject_unknown_kind(data, {"trigger", "optional", *EVENT_KINDS}, EVENT_KINDS,
                                    "event")
        return _empty_for_null(data, EVENT_KINDS)

    @model_validator(mode="after")
    def _one_kind(self) -> EventModel:
        _exactly_one(self, EVENT_KINDS, "event")
        return self

    @property
    def kind(self) -> str:
        """The event's name: one of `EVENT_KINDS`."""
        return _present(self, EVENT_KINDS)[0]


# ---------------------------------------------------------------------------------------
# Ego, actors, sensors, criteria
# ---------------------------------------------------------------------------------------


class EgoModel(FormatModel):
    """The car under test. On a road: `lane` and `s`; in a town: `start` and `route`."""

    lane: Annotated[int, Field(ge=0, le=b.MAX_LANES)] | None = Field(
        default=None,
        description="(road) starting lane, 0 = rightmost; must exist at `s`. Default 0.",
    )
    s: b.Station | None = Field(
        default=None,
        description="[m] (road) station of the car's centre, on the route; required on a road.",
    )
    start: TownStart | None = Field(
        default=None,
        description="(town) `[ix, iy, heading]`: junction indices and east | north | west | "
        "south; required in a town.",
    )
    route: Annotated[list[Turn], Field(max_length=b.MAX_ROUTE_TURNS)] | None = Field(
        default=None,
        description="(town) what to do at each junction met: straight | left | right | u_turn; "
        "required in a town.",
    )
    speed_kph: b.Speed = Field(
        default=0.0, description="[km/h] initial speed, >= 0, <= max_speed_kph. Default 0."
    )
    set_speed_kph: b.Speed = Field(
        description="[km/h] the driver's desired (cruise) speed, >= 0, <= max_speed_kph; required."
    )
    max_speed_kph: b.PosSpeed = Field(
        default=54.0,
        description="[km/h] vehicle speed limit, > 0. Default 54 (15 m/s, the ICCAS car).",
    )
    overtake: bool = Field(
        default=False,
        description="(road) the car may change lanes to pass a slower vehicle when the next "
        "lane is free (ICCAS lane changing). Default false: it follows.",
    )


class ActorModel(FormatModel):
    """Another road user or a static obstacle."""

    id: Identifier = Field(description="Unique name, [a-z0-9_]+; required.")
    type: ActorTypeName = Field(
        description="car | truck | pedestrian | obstacle (a static box); required. "
        "A pedestrian is a 0.5 x 0.6 x 1.75 m body; its speed_kph is a walking speed."
    )
    model: VehicleModelName | None = Field(
        default=None,
        description="(car, truck) the body from the vehicle catalogue, real dimensions: "
        "small_car | sedan | suv | van | motorbike (type car), bus | rigid_truck | "
        "semi_trailer (type truck). Default: sedan for a car, rigid_truck for a truck.",
    )
    lane: int | None = Field(
        default=None,
        description="(road) lane index: 0 = rightmost of the ego's direction; -1, -2, ... "
        "oncoming lanes from the centre line out. Must exist at `s`. Default 0.",
    )
    s: b.Station | None = Field(
        default=None,
        description="[m] (road) station of the actor's centre, on the route; required on a road.",
    )
    offset: b.Offset = Field(
        default=0.0,
        description="[m] lateral offset from the lane centre, left positive. Default 0.",
    )
    start: TownStart | None = Field(
        default=None, description="(town) `[ix, iy, heading]` as for the ego."
    )
    route: Annotated[list[Turn], Field(max_length=b.MAX_ROUTE_TURNS)] | None = Field(
        default=None, description="(town) turns as for the ego.")
    speed_kph: b.Speed = Field(
        default=0.0,
        description="[km/h] initial speed, >= 0; an obstacle must not move. Default 0.",
    )
    actions: list[ActionModel] = Field(
        default_factory=list, max_length=b.MAX_ACTIONS,
        description="Scripted actions, each fires once when its trigger first holds. "
        "Default none: the actor keeps its lane and speed.",
    )

    @model_validator(mode="after")
    def _model_fits_type(self) -> ActorModel:
        """A catalogue model only on a vehicle, and of a class its type takes."""
        if self.model is None:
            return self
        classes = TYPE_CLASSES.get(self.type)
        if classes is None:
            raise problem(f"only a car or truck takes a model (this is a {self.type})",
                          key="model")
        model = CATALOGUE[self.model]
        if model.cls not in classes:
            fits = next(t for t, c in TYPE_CLASSES.items() if model.cls in c)
            raise problem(f"a {self.model} needs type: {fits}, not {self.type}", key="model")
        return self


GnssPreset = Literal["rtk", "consumer", "degraded"]
MAX_GNSS_BIAS = 50.0  # [m] the largest GNSS bias (constant or wandering 1-sigma) a file may set


class GnssModel(FormatModel):
    """The GNSS receiver: a preset and / or its knobs. Knobs override the preset's values;
    knobs without a preset start from `rtk` (what a `gnss:` block meant before presets);
    no `gnss:` block at all is the `consumer` preset."""

    preset: GnssPreset | None = Field(
        default=None,
        description="Named receiver: `rtk` (5 cm white noise, no bias), `consumer` (a "
        "wandering bias of 1.2 m 1-sigma per axis, 60 s correlation time, 0.3 m noise, "
        "heading from motion, outages) or `degraded` (3 m, 30 s, 0.8 m, frequent "
        "outages). Default: `rtk` when knobs are given, else `consumer`.",
    )
    sigma: Annotated[float, Field(ge=0, le=MAX_GNSS_BIAS)] | None = Field(
        default=None, description="[m] 1-sigma white position noise per axis, >= 0. "
        "Default: the preset's (rtk 0.05, consumer 0.3, degraded 0.8)."
    )
    heading_sigma_deg: b.HeadingSigma | None = Field(
        default=None, description="[deg] 1-sigma heading noise, >= 0. Default: the "
        "preset's (rtk 0.2, consumer 0.3, degraded 1.0)."
    )
    bias: Annotated[
        tuple[Annotated[float, Field(strict=True, ge=-MAX_GNSS_BIAS, le=MAX_GNSS_BIAS)],
              Annotated[float, Field(strict=True, ge=-MAX_GNSS_BIAS, le=MAX_GNSS_BIAS)]],
        Field(strict=False),
    ] | None = Field(default=None, description="[m] constant (x, y) offset, each within "
                     "+-50. Default [0, 0].")
    bias_sigma: Annotated[float, Field(ge=0, le=MAX_GNSS_BIAS)] | None = Field(
        default=None, description="[m] stationary 1-sigma of the wandering (Gauss-Markov) "
        "bias per axis, 0..50. Default: the preset's (rtk 0, consumer 1.2, degraded 3)."
    )
    bias_tau: b.Duration | None = Field(
        default=None, description="[s] correlation time of the wandering bias, > 0. "
        "Default: the preset's (60, degraded 30)."
    )
    velocity_sigma: b.VelocitySigma | None = Field(
        default=None, description="[m/s] 1-sigma velocity noise; > 0: the heading is the "
        "course over ground, noisier at low speed, none at a standstill. Default: the "
        "preset's (rtk 0, consumer 0.15, degraded 0.3)."
    )
    dropout_rate: b.DropoutRate | None = Field(
        default=None, description="[1/s] outages started per second, >= 0. Default: the "
        "preset's (rtk 0, consumer 1/300, degraded 1/30)."
    )
    dropout_duration: b.Duration | None = Field(
        default=None, description="[s] mean length of an outage, > 0. Default: the "
        "preset's (2, degraded 3)."
    )


class LidarModel(FormatModel):
    """LiDAR noise (the beam layout comes from `--profile`); keys left out take their
    defaults."""

    range_sigma: b.RangeSigma = Field(
        default=0.02, description="[m] 1-sigma range noise, >= 0. Default 0.02."
    )
    dropout: Fraction = Field(
        default=0.0, description="[-] fraction of rays lost, 0..1. Default 0."
    )


class SensorsModel(FormatModel):
    """Sensor noise; keys left out take their defaults (`--profile` chooses the sensors,
    not their noise)."""

    gnss: GnssModel | None = Field(
        default=None, description="GNSS receiver `{preset, sigma, heading_sigma_deg, bias, "
        "bias_sigma, bias_tau, velocity_sigma, dropout_rate, dropout_duration}`; default: "
        "the `consumer` preset."
    )
    lidar: LidarModel | None = Field(
        default=None, description="LiDAR noise `{range_sigma, dropout}`."
    )


def _criteria_model() -> type[FormatModel]:
    """The `criteria:` section: one optional key per criteria declaration that has one
    (`avsim.criteria.registry`), with the declaration's setting type and description."""
    fields: dict[str, Any] = {
        str(d.key): (d.setting | None,
                     Field(default=None, description=d.doc, examples=[d.example]))
        for d in keyed()
    } | {
        str(d.switch): (StrictBool | None, Field(
            default=None, examples=[False],
            description=f"false turns the always-on `{d.switch}` off; true (the default) "
            "keeps it."))
        for d in switches()
    }
    return create_model("CriteriaModel", __base__=FormatModel, __module__=__name__,
                        __doc__="Optional criteria; the default criteria always apply.",
                        **fields)


if TYPE_CHECKING:  # a model made at import: its keys are the registry's, read with getattr
    CriteriaModel = FormatModel
else:
    CriteriaModel = _criteria_model()


# ---------------------------------------------------------------------------------------
# Campaigns: `vary`
# ---------------------------------------------------------------------------------------

DISTRIBUTION_KINDS = ("uniform", "normal", "integers", "choice")
Pair = Annotated[list[float], Field(min_length=2, max_length=2)]
IntPair = Annotated[list[int], Field(min_length=2, max_length=2)]


class NormalModel(FormatModel):
    """A normal law clipped to [min, max] (a draw outside is set to the bound it passed)."""

    mean: float = Field(description="The law's mean, in the key's unit; required.")
    sd: float = Field(gt=0, description="The law's standard deviation, > 0; required.")
    min: float = Field(description="The least value drawn (lower draws are clipped); required.")
    max: float = Field(description="The most value drawn (higher draws are clipped); required.")

    @model_validator(mode="after")
    def _ordered(self) -> NormalModel:
        if not self.min <= self.mean <= self.max:
            raise problem(f"needs min <= mean <= max, got {self.min}, {self.mean}, {self.max}")
        return self


class DistributionModel(FormatModel):
    """How a campaign draws one key of `vary`: exactly one law."""

    model_config = ConfigDict(json_schema_extra=_one_of(DISTRIBUTION_KINDS))

    uniform: Pair | None = Field(default=None, description="[lo, hi]: uniform over lo..hi.")
    normal: NormalModel | None = Field(default=None, description="{mean, sd, min, max}: "
                                       "normal, clipped to min..max.")
    integers: IntPair | None = Field(default=None, description="[lo, hi]: an integer of "
                                     "lo..hi (both included), each as likely.")
    choice: list[Any] | None = Field(
        default=None, min_length=1, max_length=MAX_CHOICES,
        description=f"[v1, v2, ...]: one of the values (at most {MAX_CHOICES}); for a key "
        "of several comma-joined paths each value is a list, one item per path.")
    weights: list[Annotated[float, Field(ge=0)]] | None = Field(
        default=None, max_length=MAX_CHOICES,
        description="With `choice`: each value's weight (>= 0, not all 0). Default: equal.")

    @model_validator(mode="before")
    @classmethod
    def _known_kind(cls, data: Any) -> Any:
        return _reject_unknown_kind(data, {*DISTRIBUTION_KINDS, "weights"},
                                    DISTRIBUTION_KINDS, "distribution")

    @model_validator(mode="after")
    def _one_law(self) -> DistributionModel:
        kind = _exactly_one(self, DISTRIBUTION_KINDS, "distribution")
        bounds = self.uniform if kind == "uniform" else self.integers
        if bounds is not None and bounds[0] > bounds[1]:
            raise problem(f"needs lo <= hi, got [{bounds[0]}, {bounds[1]}]", key=kind)
        if self.weights is not None:
            if self.choice is None:
                raise problem("weights go with a choice", key="weights")
            if len(self.weights) != len(self.choice):
                raise problem(f"{len(self.weights)} weights for {len(self.choice)} values",
                              key="weights")
            if sum(self.weights) <= 0:
                raise problem("the weights are all 0", key="weights")
        return self

    @property
    def kind(self) -> str:
        """The law: uniform, normal, integers or choice."""
        return _present(self, DISTRIBUTION_KINDS)[0]


# ---------------------------------------------------------------------------------------
# The whole file
# ---------------------------------------------------------------------------------------


class StackModel(FormatModel):
    """Which stack drives the car (`avsim.stack.StackChoice`): each key a factory,
    `package.module:factory` or an installed stack's name (entry point group
    `avsim.stacks`); left out or `avsim`: the bundled one."""

    model_config = ConfigDict(extra="forbid")

    stack: StackSpec | None = Field(
        default=None, description="A whole stack of one's own (every stage); not with the "
        "stage keys. Default: the bundled stack.")
    perception: StackSpec | None = Field(
        default=None, description="The perception stage (frames in, PlannerInput out). "
        "Default: the bundled one.")
    planner: StackSpec | None = Field(
        default=None, description="The planner stage (PlannerInput in, Plan out). Default: "
        "the bundled one.")
    controller: StackSpec | None = Field(
        default=None, description="The controller stage (Plan in, VehicleCommand out). "
        "Default: the bundled one.")
    privileged: bool = Field(
        default=False, description="Privileged truth mode: the car also has the `truth` "
        "sensor, which hands the stack the ground truth (its pose, every object's box) at "
        "40 Hz; every result of the run says so. Default false.")

    @model_validator(mode="after")
    def _whole_or_stages(self) -> StackModel:
        if self.stack not in (None, BUNDLED) and any(
                s not in (None, BUNDLED) for s in (self.perception, self.planner,
                                                  self.controller)):
            raise ValueError("a whole stack replaces every stage: give either `stack` or "
                             "the stages to replace, not both")
        if self.perception == TRUTH_PERCEPTION and not self.privileged:
            raise problem(f"{TRUTH_PERCEPTION} reads the ground truth: it needs privileged "
                          "truth mode (stack.privileged: true, or --privileged)",
                          key="perception")
        return self


class ScenarioModel(FormatModel):
    """A scenario file, format `avsim/1`: exactly one map (`road` or `town`), the ego, and
    optionally actors, sensors, events and criteria."""

    model_config = ConfigDict(json_schema_extra=_one_of(("road", "town")))

    format: Literal["avsim/1"] = Field(description="The format version, `avsim/1`; required.")
    name: ScenarioName = Field(
        description=f"Scenario name, [a-z0-9_]+, at most {b.MAX_NAME_LENGTH} characters; "
        "required.")
    description: str = Field(default="", description="One line for humans. Default empty.")
    situation: Situation = Field(
        default="other",
        description="normal_driving | lane_change | cut_in_out | traffic_jam | sudden_stop | "
        "external_disturbance | decs_route | town | other. Default other.",
    )
    duration: b.Duration = Field(description="[s] simulated time limit, > 0; required.")
    seed: b.Seed = Field(default=0, description="Random seed, >= 0. Default 0.")
    road: RoadModel | None = Field(
        default=None, description="Map kind 1, a route road; give this or `town`."
    )
    town: TownModel | None = Field(
        default=None,
        description="Map kind 2, a grid town; give this or `road`. Not supported yet.",
    )
    ego: EgoModel = Field(description="The car under test; required.")
    actors: list[ActorModel] = Field(
        default_factory=list, max_length=b.MAX_ACTORS, description="Other road users. Default none."
    )
    sensors: SensorsModel = Field(
        default_factory=SensorsModel,
        description="Sensor noise; keys left out come from `--profile`. Default: the profile's.",
    )
    events: list[EventModel] = Field(
        default_factory=list, max_length=b.MAX_EVENTS,
        description="What happens to the ego car: an accelerator override, a flat tyre, "
        "sensor faults. Default none.",
    )
    stack: StackModel = Field(
        default_factory=StackModel,
        description="Which stack drives the car: `stack` (a whole stack), or `perception`, "
        "`planner`, `controller` (stages replaced), each `package.module:factory` or an "
        "installed stack's name; `--stack` and the stage options override it. Default: the "
        "bundled stack.")
    criteria: CriteriaModel = Field(
        default_factory=CriteriaModel,
        description="Criteria to add or tune, by key: "
        + ", ".join(setting_keys())
        + ". The default criteria always apply. Default: none added.",
    )
    grid: dict[GridPath, GridValues] = Field(
        default_factory=dict,
        description="A test grid: dotted key paths of this file (list indices as numbers) "
        "and the values each takes, as `avsim sweep --set` gives them; several paths joined "
        "by commas take their values together (each value a list, one item per path). "
        "`avsim suite` runs "
        f"every point (at most {MAX_GRID_POINTS}, the last key varying fastest, named "
        "NAME_000, NAME_001, ...); `avsim run` runs the file's own values. Default: none.",
    )

    vary: dict[GridPath, DistributionModel] = Field(
        default_factory=dict, max_length=MAX_VARY_KEYS,
        description="A campaign's laws (`avsim campaign`): dotted key paths of this file (as "
        "`grid` names them) and the distribution each run draws its value from: "
        "`{uniform: [lo, hi]}`, `{normal: {mean, sd, min, max}}`, `{integers: [lo, hi]}`, "
        "`{choice: [...], weights: [...]}`; several paths joined by commas are drawn "
        f"together by a `choice` of lists. At most {MAX_VARY_KEYS} keys; not with `grid`. "
        "`avsim run` runs the file's own values. Default: none.",
    )

    @model_validator(mode="after")
    def _grid_size(self) -> ScenarioModel:
        for key, values in self.grid.items():
            paths = grid_paths(key)
            for path in paths:
                if path.split(".")[0] in ("grid", "format", "name"):
                    raise problem(f"{path!r}: a grid cannot vary this key", key="grid")
            if len(paths) > 1 and any(not isinstance(v, list) or len(v) != len(paths)
                                      for v in values):
                raise problem(f"each value must be a list of {len(paths)} (one per key)",
                              key=f"grid.{key}")
        points = math.prod(len(values) for values in self.grid.values())
        if points > MAX_GRID_POINTS:
            raise problem(f"{points} points: at most {MAX_GRID_POINTS}", key="grid")
        return self

    @model_validator(mode="after")
    def _vary_laws(self) -> ScenarioModel:
        if self.vary and self.grid:
            raise problem("a file has a grid or a vary section, not both", key="vary")
        drawn: set[str] = set()
        for key, law in self.vary.items():
            paths = grid_paths(key)
            for path in paths:
                if path.split(".")[0] in ("grid", "vary", "format", "name"):
                    raise problem(f"{path!r}: a campaign cannot vary this key", key=f"vary.{key}")
                if path in drawn:
                    raise problem(f"{path!r} is drawn twice", key=f"vary.{key}")
                drawn.add(path)
            if len(paths) > 1 and (law.choice is None or any(
                    not isinstance(v, list) or len(v) != len(paths) for v in law.choice)):
                raise problem(f"several keys are drawn together by a choice of lists of "
                              f"{len(paths)} (one item per key)", key=f"vary.{key}")
        return self

    @model_validator(mode="after")
    def _one_map(self) -> ScenarioModel:
        if self.road is None and self.town is None:
            raise problem("a map is required: give `road` or `town`", key="road")
        if self.road is not None and self.town is not None:
            raise problem("give either `road` or `town`, not both", key="town")
        return self
