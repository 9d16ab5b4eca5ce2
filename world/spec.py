"""What a world is built from: roads or a town, the ego car's body at its start, the actors
and their scripts, the events that happen to the ego, the sensors' noise, and the seed of
the world's randomness. Validated, resolved, in SI units.

`avsim.scenario` parses and validates the user's YAML (the public format, with `*_kph` and
`*_deg` keys and defaults) and converts it into these frozen dataclasses (a scenario also
has a name, a duration, the driver's settings and its criteria: `avsim.scenario.scenario`).
Everything in `world/` builds from them; nothing here knows about files or YAML.

Conventions: metres, seconds, radians, m/s. Stations `s` are metres along the route's
reference line (the centre line of lane 0, the rightmost lane of the ego's direction) from
its start. Lateral offsets `r` are metres, left positive, from the centre of the named lane.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field

from world.actors.catalogue import VehicleModel
from world.frames import Wheel
from world.hdmap import (
    Crosswalk,
    Junction,
    LaneProfile,
    LightHead,
    LinePaint,
    Side,
    SpeedBump,
    SpeedLimitSign,
    StopSign,
    Zone,
)

# ---------------------------------------------------------------------------------------
# Road
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class SegmentSpec:
    """One piece of the route's reference line, laid after the previous one.

    A straight has `curvature == 0`; an arc has a signed constant curvature `1 / radius`
    (> 0 turns left). `length` is measured along the reference line (lane 0's centre).
    The lane layout fields are resolved (road defaults already applied).
    """

    length: float  # [m] along the reference line, > 0
    curvature: float  # [1/m] signed, > 0 turns left, 0 for a straight
    lanes: int  # [-] driving lanes in the ego's direction, >= 1; lane 0 is the rightmost
    oncoming_lanes: int  # [-] lanes in the other direction, left of the yellow centre line
    lane_width: float  # [m] every lane's width
    shoulder: float  # [m] paved right shoulder's width, 0 for none
    speed_limit: float | None = None  # [m/s] posted at the segment's start; None: unchanged
    zone: Zone | None = None  # scenery style; None: as the segment before (highway at start)
    exit: Side | None = None  # the route leaves the road here by an exit on this side (right
    #   only: `world.map.road`); the road goes on straight as scenery
    start: tuple[float, float, float] | None = None  # [m, m, rad] the piece's exact start
    #   pose (x, y, heading) where the map kind knows it (an OpenDRIVE road's arc spline);
    #   None: laid from the end of the piece before
    paint: LinePaint | None = None  # the map file's lane lines; None: the road's own rules
    profile: LaneProfile | None = None  # lane boundaries that change along the segment (a
    #   map file's polynomial widths and lane offsets); None: uniform, `lane_width` each


@dataclass(frozen=True, slots=True)
class TrafficLightSpec:
    """A signal for the traffic on the route at stop line `s`, with its signal plan (ground
    truth: the world lights its lamps by it, the criteria judge by it; the stack's map has
    only the light's place, `world.hdmap.TrafficLight`). The cycle starts green: green, then
    yellow, then red; `phase` is the time into the cycle at t = 0."""

    s: float  # [m] station of the stop line
    green: float  # [s]
    yellow: float  # [s]
    red: float  # [s]
    phase: float  # [s] time into the cycle at t = 0
    head: LightHead | None = None  # None: the map builder places it (`world.map.road`)

    @property
    def cycle(self) -> float:
        """[s] green + yellow + red."""
        return self.green + self.yellow + self.red


FeatureSpec = SpeedLimitSign | StopSign | Crosswalk | SpeedBump | TrafficLightSpec


@dataclass(frozen=True, slots=True)
class BuildingsSpec:
    """Buildings beside a road (`world.scene.scenery`)."""

    density: float  # [-] 0..1, fraction of the roadside frontage that is built up
    setback: float  # [m] from the road's outer edge to the building front


@dataclass(frozen=True, slots=True)
class RoadSpec:
    """A route road (`world.map.road`), or a town route compiled into one (`world.map.town`)."""

    segments: tuple[SegmentSpec, ...]  # in route order
    speed_limit: float  # [m/s] posted at s = 0
    features: tuple[FeatureSpec, ...] = ()  # signs, crosswalks, bumps, lights, by station
    buildings: BuildingsSpec | None = None  # None: no buildings
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)  # [m, m, rad] map-frame (x, y, heading)
    #   of the reference line's start
    junctions: tuple[Junction, ...] = ()  # a town route's junctions, by station


@dataclass(frozen=True, slots=True)
class LightTiming:
    """A town junction's signal plan: the east-west approaches get `green`, `yellow`, then
    red while the north-south ones get theirs; `all_red` [s] between the two."""

    green: float = 15.0  # [s]
    yellow: float = 3.0  # [s]
    all_red: float = 2.0  # [s]

    @property
    def cycle(self) -> float:
        """[s] both directions' green, yellow and all-red."""
        return 2.0 * (self.green + self.yellow + self.all_red)


@dataclass(frozen=True, slots=True)
class TownSpec:
    """A grid town (map kind 2): streets along x = ix * block and y = iy * block, junction
    (ix, iy) at their crossing, ix in 0..blocks_x, iy in 0..blocks_y (`world.map.town`)."""

    blocks_x: int  # [-] blocks along x
    blocks_y: int  # [-] blocks along y
    block: float  # [m] junction spacing
    lanes: int  # [-] per direction
    lane_width: float  # [m] every lane's width
    speed_limit: float  # [m/s] on every street
    junctions: str  # "stop_signs" | "traffic_lights" | "mixed" (lights where ix + iy is even)
    lights: LightTiming = field(default_factory=LightTiming)


# ---------------------------------------------------------------------------------------
# Triggers, actions and events
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class TimeTrigger:
    """Holds from sim time `time` on."""

    time: float  # [s] simulated time


@dataclass(frozen=True, slots=True)
class EgoStationTrigger:
    """Holds once the ego's centre has reached station `s`."""

    s: float  # [m] the ego's centre station reached


@dataclass(frozen=True, slots=True)
class GapTrigger:
    """Holds once an actor's gap to the ego has fallen to `gap` (actors only)."""

    gap: float  # [m] bumper-to-bumper distance from the actor to the ego along the route


@dataclass(frozen=True, slots=True)
class AfterTrigger:
    """Holds `delay` after item `index` of the same list ended."""

    index: int  # [-] an earlier action of the same actor (or event of the ego's list)
    delay: float  # [s] after that action ended


Trigger = TimeTrigger | EgoStationTrigger | GapTrigger | AfterTrigger


@dataclass(frozen=True, slots=True)
class SpeedAction:
    speed: float  # [m/s] target speed
    accel: float  # [m/s^2] magnitude used to reach it (> 0)


@dataclass(frozen=True, slots=True)
class LaneChangeAction:
    to_lane: int  # [-] lane index on the actor's route
    lateral_speed: float  # [m/s] > 0


@dataclass(frozen=True, slots=True)
class WalkAction:
    to_offset: float  # [m] lateral offset from the actor's lane centre to walk to
    speed: float  # [m/s] walking speed across


@dataclass(frozen=True, slots=True)
class StopAction:
    decel: float = 6.0  # [m/s^2] braking to rest


Action = SpeedAction | LaneChangeAction | WalkAction | StopAction


@dataclass(frozen=True, slots=True)
class ActionSpec:
    """An actor's action and the trigger that fires it (`world.actors.behaviour`)."""

    trigger: Trigger
    action: Action
    optional: bool = False  # the run may end without it having fired


class ActorType(enum.Enum):
    CAR = "car"
    TRUCK = "truck"
    PEDESTRIAN = "pedestrian"
    OBSTACLE = "obstacle"


@dataclass(frozen=True, slots=True)
class ActorSpec:
    """A scripted actor (`world.actors`) and where it starts."""

    id: str  # unique in the scenario
    type: ActorType
    lane: int  # lane index on the route (pedestrians: the lane their offset is measured from)
    s: float  # [m] station of the actor's centre
    offset: float  # [m] lateral, left positive, from the lane centre
    speed: float  # [m/s] initial speed
    actions: tuple[ActionSpec, ...] = ()  # in the scenario's order (`after` indexes them)
    road: RoadSpec | None = None  # in a town: the actor's own route (lane, s, offset on it)
    model: VehicleModel | None = None  # a vehicle's body (`world.actors.catalogue`); None:
    #   its type's default model (a car or truck), or no vehicle (pedestrian, obstacle)
    size: tuple[float, float, float] | None = None  # [m] length, width, height of a
    #   pedestrian's or an obstacle's box (a scenario file's bounding box); None: the type's
    #   (`world.actors.bodies.SIZES`)
    against: bool = False  # drives against its lane's direction of travel (a scenario
    #   file's heading turned half a turn from the lane's)
    facing: float = 0.0  # [rad] a pedestrian's initial heading from its lane's direction of
    #   travel, left positive (a scenario file's orientation; it turns to where it walks)


@dataclass(frozen=True, slots=True)
class AcceleratorOverride:
    """The accelerator pedal held (`world.ego.events`)."""

    pedal: float  # [-] 0..1, pedal position
    duration: float  # [s] held for


@dataclass(frozen=True, slots=True)
class FlatTire:
    """A punctured tyre (`world.ego.body`)."""

    wheel: Wheel


@dataclass(frozen=True, slots=True)
class CameraBlackout:
    """A camera's images go black (a dead sensor or a cut cable: `world.sensors.faults`)."""

    camera: str  # the camera's name ("front", "left", "right")
    duration: float  # [s] how long


@dataclass(frozen=True, slots=True)
class CameraFreeze:
    """A camera keeps sending its last image (a hung image pipeline: `world.sensors.faults`)."""

    camera: str  # the camera's name
    duration: float  # [s] how long


@dataclass(frozen=True, slots=True)
class CameraOcclusion:
    """Part of a camera's view is covered by something opaque and dark (mud, a leaf, tape:
    `world.sensors.faults`): a strip of the image from one side."""

    camera: str  # the camera's name
    fraction: float  # [-] 0..1, of the image's width covered
    side: Side  # the side of the image the strip is on (left / right, as the car looks)
    duration: float  # [s] how long


@dataclass(frozen=True, slots=True)
class SensorDelay:
    """A sensor's data arrive later than they should (a congested bus, an overloaded
    driver: `world.sensors.faults`): each delivery carries its capture from `delay` earlier."""

    sensor: str  # a camera's name or "lidar"
    delay: float  # [s] added to its latency
    duration: float  # [s] how long


@dataclass(frozen=True, slots=True)
class LidarOutage:
    """The LiDAR sends no scan (`world.sensors.faults`)."""

    duration: float  # [s] how long


@dataclass(frozen=True, slots=True)
class GnssOutage:
    """The GNSS receiver has no fix: every epoch is flagged invalid
    (`world.sensors.faults`)."""

    duration: float  # [s] how long


@dataclass(frozen=True, slots=True)
class GnssJump:
    """The GNSS fixes jump by a constant offset (a multipath lock or a spoofed signal:
    `world.sensors.faults`)."""

    offset: tuple[float, float]  # [m] (x, y) added to every fix, map frame
    duration: float  # [s] how long


SensorFault = (CameraBlackout | CameraFreeze | CameraOcclusion | LidarOutage | GnssOutage
               | GnssJump | SensorDelay)
SENSOR_FAULTS = (CameraBlackout, CameraFreeze, CameraOcclusion, LidarOutage, GnssOutage, GnssJump,
                 SensorDelay)
EgoEvent = AcceleratorOverride | FlatTire | SensorFault


@dataclass(frozen=True, slots=True)
class EventSpec:
    """An event that happens to the ego car and the trigger that fires it."""

    trigger: Trigger
    event: EgoEvent
    optional: bool = False  # the run may end without it having fired


# ---------------------------------------------------------------------------------------
# Ego, sensors, the whole world
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class EgoSpec:
    """The ego car's body at the start (where the driver wants to go is not the world's:
    `avsim.scenario.scenario.DriverSettings`)."""

    lane: int  # [-] starting lane index on the route
    s: float  # [m] station of the car's centre
    speed: float  # [m/s] initial speed
    max_speed: float  # [m/s] vehicle limit
    engaged: bool = True  # the automated driving function's switch at the start (off: the
    #   driver holds the speed until a storyboard activates the car's controller)
    scripted: bool = False  # the scenario's script moves it as it moves an actor (a
    #   kinematic body, `world.ego.scripted`), no stack drives it
    offset: float = 0.0  # [m] its centre's start left of its lane's centre (an OpenSCENARIO
    #   file's lane offset); the stack, driving, steers for the centre


@dataclass(frozen=True, slots=True)
class GnssSpec:
    """The GNSS receiver's errors (`world.sensors.gnss`); the defaults are the `consumer`
    preset (`GNSS_PRESETS`).

    Position error per axis (x, y of the map frame) = ``bias`` + a wandering bias (a
    first-order Gauss-Markov process of stationary 1-sigma ``bias_sigma`` and correlation
    time ``bias_tau``) + white noise ``sigma``. Heading error = white noise of 1-sigma
    ``heading_sigma``, and, with ``velocity_sigma`` > 0, of ``atan(velocity_sigma / speed)``
    on top (a single-antenna receiver's heading is its course over ground, from its velocity:
    none at a standstill). Outages start at ``dropout_rate`` per second and last
    ``dropout_duration`` seconds on average (both exponential); a fix in an outage is
    flagged invalid (`world.frames.GnssFix.valid`).
    """

    sigma: float = 0.3  # [m] 1-sigma white position noise per axis
    heading_sigma: float = 0.0052359878  # [rad] 1-sigma heading noise floor (0.3 deg)
    bias: tuple[float, float] = (0.0, 0.0)  # [m] constant (x, y) offset (the bias's mean)
    bias_sigma: float = 1.2  # [m] stationary 1-sigma of the wandering bias, per axis
    bias_tau: float = 60.0  # [s] the wandering bias's correlation time
    velocity_sigma: float = 0.15  # [m/s] 1-sigma velocity noise (heading from motion); 0: none
    dropout_rate: float = 1.0 / 300.0  # [1/s] outages started per second of fix
    dropout_duration: float = 2.0  # [s] mean length of an outage

    @property
    def stated_sigma(self) -> float:
        """[m] the 1-sigma horizontal accuracy per axis the receiver states with each fix
        (like u-blox's hAcc): its white noise and wandering bias together. A constant
        ``bias`` is an error it does not know of."""
        return math.hypot(self.sigma, self.bias_sigma)


GNSS_PRESETS: dict[str, GnssSpec] = {
    # RTK (e.g. u-blox ZED-F9P with corrections: 0.01 m + 1 ppm CEP in its data sheet; 5 cm
    # 1-sigma for a moving car with float fixes and multipath; dual-antenna heading 0.2 deg).
    # Exactly what a `gnss:` block meant before the presets (white noise, no wander).
    "rtk": GnssSpec(sigma=0.05, heading_sigma=0.0034906585, bias_sigma=0.0, velocity_sigma=0.0,
                    dropout_rate=0.0),
    # consumer single-frequency / dual-frequency receiver without corrections (u-blox
    # NEO-M8: 2.5 m CEP autonomous, 2.0 m CEP with SBAS; ZED-F9P: 1.5 m CEP PVT; both:
    # velocity 0.05 m/s, heading 0.3 deg at 30 m/s, 50 %). 1.2 m wandering bias + 0.3 m noise
    # per axis is 1.24 m 1-sigma, 1.46 m CEP (CEP = 1.1774 sigma for a circular Gaussian).
    "consumer": GnssSpec(),
    # the same receiver in a street canyon / under trees: multipath, fewer satellites
    # (several metres CEP, frequent outages)
    "degraded": GnssSpec(sigma=0.8, heading_sigma=0.0174532925, bias_sigma=3.0, bias_tau=30.0,
                         velocity_sigma=0.3, dropout_rate=1.0 / 30.0, dropout_duration=3.0),
}


@dataclass(frozen=True, slots=True)
class LidarNoiseSpec:
    """The LiDAR's noise (`world.sensors`)."""

    range_sigma: float = 0.02  # [m] range noise, 1-sigma
    dropout: float = 0.0  # [-] fraction of rays lost


@dataclass(frozen=True, slots=True)
class SensorsSpec:
    """The sensors' noise (`world.sensors`)."""

    gnss: GnssSpec = field(default_factory=GnssSpec)  # the `consumer` preset
    lidar: LidarNoiseSpec = field(default_factory=LidarNoiseSpec)


@dataclass(frozen=True, slots=True)
class SceneryObjectSpec:
    """A static solid of the scenery in the map frame (an OpenDRIVE road object): a box, an
    upright cylinder or the prism of an outline. The cameras and the LiDAR see it, and
    touching it is a collision."""

    type: str  # the file's object type ("pole", "tree", "railing", ...): names its colour
    centre: tuple[float, float, float]  # [m] map frame, the solid's middle
    yaw: float  # [rad] of its x axis (length), ccw from map +x
    half_extents: tuple[float, float, float]  # [m] box: along, across, up; a cylinder:
    #   (radius, radius, half its height); a prism: its points' bounding box's
    round: bool = False  # an upright cylinder of radius half_extents[0]
    hull: tuple[tuple[float, float, float], ...] = ()  # [m] a prism's corner points
    #   relative to `centre` (map axes, yaw 0): the solid is their convex hull


@dataclass(frozen=True, slots=True)
class WorldSpec:
    """A whole world: `World(spec)` builds it (`world.world`)."""

    road: RoadSpec  # the ego's route (in a town: its route through the town)
    ego: EgoSpec
    seed: int = 0  # of the world's randomness: scenery layout, sensor noise
    actors: tuple[ActorSpec, ...] = ()
    sensors: SensorsSpec = field(default_factory=SensorsSpec)
    events: tuple[EventSpec, ...] = ()  # what happens to the ego car
    town: TownSpec | None = None  # map kind 2: `road` is then the ego's route through it
    scenery_roads: tuple[RoadSpec, ...] = ()  # roads drawn in the world (surface and paint)
    #   but not on the HD map the stack reads, with no traffic and no traffic rules from them
    #   (an OpenDRIVE dual carriageway's far side: `world.map.opendrive.far_side`)
    scenery_objects: tuple[SceneryObjectSpec, ...] = ()  # static solids beside the roads
    #   (an OpenDRIVE file's road objects: `world.map.opendrive.object_layout`)
